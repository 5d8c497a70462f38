#include "sbaslam/core/stop_signal.h"

#include <atomic>
#include <csignal>
#include <mutex>

namespace sbaslam {
namespace {

// Read by other threads while the handler may write it: an atomic that needs no lock is both
// thread-safe and async-signal-safe.
std::atomic<int> g_received{0};
static_assert(std::atomic<int>::is_always_lock_free);
std::mutex g_guards_mutex;
int g_guards = 0;
struct sigaction g_previous_int, g_previous_term;

extern "C" void on_stop_signal(int signal_number) {
  if (g_received.load() != 0) {
    // Asked twice: end now, with the signal's default action (only async-signal-safe calls).
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
    return;
  }
  g_received.store(signal_number);
}

}  // namespace

StopSignalGuard::StopSignalGuard() {
  const std::lock_guard<std::mutex> lock(g_guards_mutex);
  if (g_guards++ > 0) return;
  g_received.store(0);
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

StopSignalGuard::~StopSignalGuard() {
  const std::lock_guard<std::mutex> lock(g_guards_mutex);
  if (--g_guards > 0) return;
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

int StopSignalGuard::received() const {
  return g_received.load();
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
