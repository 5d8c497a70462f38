#include "sbaslam/core/parallel_tasks.h"

#include <gtest/gtest.h>

#include <atomic>
#include <opencv2/core/utility.hpp>
#include <stdexcept>
#include <vector>

namespace sbaslam {
namespace {

TEST(RunTasksInParallel, RunsEveryTaskOnce) {
  std::vector<std::atomic<int>> runs(50);
  std::vector<std::function<void()>> tasks;
  for (std::size_t i = 0; i < runs.size(); ++i) tasks.push_back([&runs, i] { ++runs[i]; });
  run_tasks_in_parallel(tasks);
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].load(), 1) << "task " << i;
  run_tasks_in_parallel({});  // nothing to do is not an error
}

TEST(RunTasksInParallel, RethrowsAfterTheOtherTasksRan) {
  std::atomic<int> ran{0};
  std::vector<std::function<void()>> tasks{[] { throw std::runtime_error("first task"); }};
  for (int i = 0; i < 20; ++i) tasks.push_back([&ran] { ++ran; });
  EXPECT_THROW(run_tasks_in_parallel(tasks), std::runtime_error);
  EXPECT_EQ(ran.load(), 20);
}

// No more tasks at once than OpenCV has threads, and an OpenCV parallel loop inside a task (as
// the dnn forward pass has) completes.
TEST(RunTasksInParallel, RunsNoMoreTasksAtOnceThanOpenCvHasThreads) {
  std::atomic<int> running{0}, most{0};
  std::vector<std::function<void()>> tasks;
  for (int i = 0; i < 8; ++i)
    tasks.push_back([&] {
      const int now = ++running;
      int seen = most.load();
      while (now > seen && !most.compare_exchange_weak(seen, now)) {
      }
      cv::parallel_for_(cv::Range(0, 1000), [](const cv::Range&) {});
      volatile double sink = 0.0;
      for (int k = 0; k < 200000; ++k) sink = sink + k;
      --running;
    });
  run_tasks_in_parallel(tasks);
  EXPECT_GE(most.load(), 1);
  EXPECT_LE(most.load(), std::max(1, cv::getNumThreads()));
}

}  // namespace
}  // namespace sbaslam
