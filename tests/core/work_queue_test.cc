#include "sbaslam/core/work_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace sbaslam {
namespace {

TEST(WorkQueueTest, LockStepTakesInOrderUntilEmpty) {
  WorkQueue<int> queue;
  for (int i = 1; i <= 3; ++i) queue.push(i);
  EXPECT_EQ(queue.size(), 3u);
  std::vector<int> taken;
  while (const std::optional<int> item = queue.try_take()) taken.push_back(*item);
  EXPECT_EQ(taken, (std::vector<int>{1, 2, 3}));
  EXPECT_TRUE(queue.idle());
}

TEST(WorkQueueTest, PushRunsItsHookOnceWithTheItem) {
  WorkQueue<int> queue;
  int hook_runs = 0;
  queue.push(3, [&] { ++hook_runs; });
  EXPECT_EQ(hook_runs, 1);
  EXPECT_EQ(queue.try_take(), std::optional<int>(3));
}

TEST(WorkQueueTest, BusyWhileTheWorkerHoldsAnItem) {
  WorkQueue<int> queue;
  queue.push(7);
  ASSERT_EQ(queue.wait_and_take(), std::optional<int>(7));
  EXPECT_EQ(queue.size(), 0u);
  EXPECT_FALSE(queue.idle());  // taken, not finished
  queue.finish_item();
  EXPECT_TRUE(queue.idle());
}

TEST(WorkQueueTest, CloseLetsTheWorkerDrainWhatIsLeftAndReturn) {
  WorkQueue<int> queue;
  std::vector<int> processed;
  std::thread worker([&] {
    while (const std::optional<int> item = queue.wait_and_take()) {
      processed.push_back(*item);
      queue.finish_item();
    }
  });
  for (int i = 0; i < 100; ++i) queue.push(i);
  queue.close();
  worker.join();
  ASSERT_EQ(processed.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(processed[static_cast<std::size_t>(i)], i);
  // A closed queue hands out nothing more until it is reopened.
  queue.push(1);
  queue.close();
  EXPECT_EQ(queue.wait_and_take(), std::optional<int>(1));
  EXPECT_EQ(queue.wait_and_take(), std::nullopt);
  queue.reopen();
  queue.push(2);
  EXPECT_EQ(queue.wait_and_take(), std::optional<int>(2));
}

TEST(WorkQueueTest, WaitUntilIdleReturnsOnlyAfterTheLastItemIsFinished) {
  WorkQueue<int> queue;
  std::atomic<int> finished{0};
  std::atomic<bool> release{false};
  std::thread worker([&] {
    while (const std::optional<int> item = queue.wait_and_take()) {
      while (!release) std::this_thread::yield();
      ++finished;
      queue.finish_item();
    }
  });
  for (int i = 0; i < 5; ++i) queue.push(i);
  std::thread releaser([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    release = true;
  });
  queue.wait_until_idle();
  EXPECT_EQ(finished.load(), 5);
  releaser.join();
  queue.close();
  worker.join();
}

}  // namespace
}  // namespace sbaslam
