#include "sbaslam/core/stop_signal.h"

#include <csignal>

#include "sbaslam/core/error.h"

namespace sbaslam {
namespace {

volatile std::sig_atomic_t g_received = 0;
bool g_installed = false;
struct sigaction g_previous_int, g_previous_term;

extern "C" void on_stop_signal(int signal_number) {
  if (g_received != 0) {
    // Asked twice: end now, with the signal's default action (only async-signal-safe calls).
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
    return;
  }
  g_received = signal_number;
}

}  // namespace

StopSignalGuard::StopSignalGuard() {
  if (g_installed) throw Error("StopSignalGuard: a guard is already installed");
  g_received = 0;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
  g_installed = true;
}

StopSignalGuard::~StopSignalGuard() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  g_installed = false;
}

int StopSignalGuard::received() const {
  return g_received;
}

const char* stop_signal_name(int signal_number) {
  switch (signal_number) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "";
  }
}

}  // namespace sbaslam
