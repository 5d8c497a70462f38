#include "sbaslam/core/side_worker.h"

#include <pthread.h>
#include <sched.h>

#include <utility>

namespace sbaslam {

SideWorker::SideWorker() : thread_([this] { loop(); }) {
  CPU_ZERO(&started_with_);
  if (pthread_getaffinity_np(thread_.native_handle(), sizeof(started_with_), &started_with_) != 0)
    CPU_ZERO(&started_with_);
}

SideWorker::~SideWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void SideWorker::run_beside(std::function<void()> there, const std::function<void()>& here) {
  keep_off_current_cpu();
  start(std::move(there));
  try {
    here();
  } catch (...) {
    wait(false);
    throw;
  }
  wait(true);
}

// The worker may use the CPUs it started with, except the one the caller is on now. A failure
// leaves the affinity as it was: slower, never wrong.
void SideWorker::keep_off_current_cpu() {
  const int cpu = sched_getcpu();
  if (cpu < 0 || cpu == excluded_cpu_) return;
  if (CPU_COUNT(&started_with_) < 2 || !CPU_ISSET(cpu, &started_with_)) return;
  cpu_set_t allowed = started_with_;
  CPU_CLR(cpu, &allowed);
  if (pthread_setaffinity_np(thread_.native_handle(), sizeof(allowed), &allowed) == 0)
    excluded_cpu_ = cpu;
}

void SideWorker::start(std::function<void()> task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = std::move(task);
    done_ = false;
  }
  wake_.notify_one();
}

void SideWorker::wait(bool rethrow) {
  std::unique_lock<std::mutex> lock(mutex_);
  finished_.wait(lock, [this] { return done_; });
  std::exception_ptr error = std::exchange(error_, nullptr);
  if (rethrow && error) std::rethrow_exception(error);
}

void SideWorker::loop() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || task_; });
      if (stop_) return;
      task = std::move(task_);
      task_ = nullptr;
    }
    std::exception_ptr error;
    try {
      task();
    } catch (...) {
      error = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = error;
      done_ = true;
    }
    finished_.notify_one();
  }
}

}  // namespace sbaslam
