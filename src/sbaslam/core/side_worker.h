#pragma once
// A background thread that runs one task beside the calling thread (the stereo extractor's right
// image while the caller extracts the left one), kept for the owner's lifetime: starting a thread
// per frame costs tens of microseconds, more on a loaded machine.

#include <sched.h>

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace sbaslam {

class SideWorker {
 public:
  SideWorker();
  ~SideWorker();
  SideWorker(const SideWorker&) = delete;
  SideWorker& operator=(const SideWorker&) = delete;

  // Runs `there` on the worker and `here` on this thread; returns when both have finished, then
  // rethrows what either threw (never earlier: `there` may use what the caller owns).
  //
  // Before waking the worker, it keeps the worker off the CPU the caller runs on, when the
  // worker was started with more than one. Linux wakes a thread on its waker's CPU when that is
  // where it last ran, and the load balancer does not move a task that has just run, so the two
  // halves took turns on one core while the other core ran the mapping thread under SCHED_IDLE:
  // real-time stereo extraction on city-loop took 17.2 ms instead of 10.8, the caller waiting
  // 6.3 ms per frame for its own core (docs/RESULTS.md, "Session 11").
  void run_beside(std::function<void()> there, const std::function<void()>& here);

  // The CPU the worker was last kept off, or -1 (started with one CPU, or the affinity could not
  // be set).
  int excluded_cpu() const { return excluded_cpu_; }

 private:
  void keep_off_current_cpu();
  void start(std::function<void()> task);
  void wait(bool rethrow);
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::function<void()> task_;
  std::exception_ptr error_;
  bool done_ = true;
  bool stop_ = false;
  cpu_set_t started_with_;  // the worker's affinity, inherited from the thread that made it
  int excluded_cpu_ = -1;   // touched by the caller's thread only
  std::thread thread_;      // last: starts after the members it uses exist
};

}  // namespace sbaslam
