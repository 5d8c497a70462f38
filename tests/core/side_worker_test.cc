#include "sbaslam/core/side_worker.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace sbaslam {
namespace {

std::vector<int> cpus_of(const cpu_set_t& set) {
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
  return cpus;
}

cpu_set_t this_thread_affinity() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(pthread_getaffinity_np(pthread_self(), sizeof(set), &set), 0);
  return set;
}

// Pins the calling thread to one CPU for its lifetime.
class PinnedTo {
 public:
  explicit PinnedTo(int cpu) : previous_(this_thread_affinity()) {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    EXPECT_EQ(pthread_setaffinity_np(pthread_self(), sizeof(one), &one), 0);
  }
  ~PinnedTo() { pthread_setaffinity_np(pthread_self(), sizeof(previous_), &previous_); }
  PinnedTo(const PinnedTo&) = delete;
  PinnedTo& operator=(const PinnedTo&) = delete;

 private:
  cpu_set_t previous_;
};

TEST(SideWorker, RunsBothTasksAndRethrowsEitherOnesExceptionAfterBothFinished) {
  SideWorker worker;
  std::atomic<int> ran{0};
  worker.run_beside([&] { ran += 1; }, [&] { ran += 10; });
  EXPECT_EQ(ran.load(), 11);

  std::atomic<bool> worker_finished{false};
  EXPECT_THROW(worker.run_beside([&] { throw std::runtime_error("there"); }, [] {}),
               std::runtime_error);
  EXPECT_THROW(
      worker.run_beside([&] { worker_finished = true; }, [] { throw std::logic_error("here"); }),
      std::logic_error);
  EXPECT_TRUE(worker_finished.load());  // the caller's exception waited for the worker
  worker.run_beside([&] { ran += 1; }, [&] { ran += 10; });  // still usable, no stale error
  EXPECT_EQ(ran.load(), 22);
}

TEST(SideWorker, KeepsTheWorkerOffTheCpuTheCallerRunsOn) {
  const std::vector<int> cpus = cpus_of(this_thread_affinity());
  if (cpus.size() < 2) GTEST_SKIP() << "needs two CPUs";
  SideWorker worker;
  for (const int caller_cpu : {cpus[0], cpus[1]}) {
    const PinnedTo pinned(caller_cpu);
    cpu_set_t worker_affinity;
    int worker_cpu = -1;
    worker.run_beside(
        [&] {
          worker_affinity = this_thread_affinity();
          worker_cpu = sched_getcpu();
        },
        [] {});
    EXPECT_EQ(worker.excluded_cpu(), caller_cpu);
    EXPECT_FALSE(CPU_ISSET(caller_cpu, &worker_affinity));
    EXPECT_EQ(cpus_of(worker_affinity).size(), cpus.size() - 1);
    EXPECT_NE(worker_cpu, caller_cpu);
  }
}

TEST(SideWorker, LeavesTheAffinityAloneWhenStartedWithOneCpu) {
  const std::vector<int> cpus = cpus_of(this_thread_affinity());
  const PinnedTo pinned(cpus[0]);
  SideWorker worker;
  cpu_set_t worker_affinity;
  worker.run_beside([&] { worker_affinity = this_thread_affinity(); }, [] {});
  EXPECT_EQ(worker.excluded_cpu(), -1);
  EXPECT_EQ(cpus_of(worker_affinity), std::vector<int>{cpus[0]});
}

}  // namespace
}  // namespace sbaslam
