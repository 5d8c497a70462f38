#pragma once
// SIGINT and SIGTERM ask a long run to stop after the current frame instead of killing it, so the
// run still writes its trajectory and run.json (a user's Ctrl-C, a job scheduler's TERM). A
// second signal of either kind ends the process at once, as users expect of a repeated Ctrl-C.

namespace sbaslam {

// Installs the handlers for its lifetime and restores the previous ones when destroyed. Guards
// that overlap (runs in several threads) share one flag: the first installs, the last restores.
class StopSignalGuard {
 public:
  StopSignalGuard();
  ~StopSignalGuard();
  StopSignalGuard(const StopSignalGuard&) = delete;
  StopSignalGuard& operator=(const StopSignalGuard&) = delete;

  // The signal (SIGINT or SIGTERM) received since the first of the overlapping guards was made,
  // or 0.
  int received() const;
};

// "SIGINT", "SIGTERM", or "" for 0.
const char* stop_signal_name(int signal_number);

}  // namespace sbaslam
