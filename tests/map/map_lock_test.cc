// The map lock's hand-over from local mapping to a waiting tracker (Map::yield_to_tracking).

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "sbaslam/map/map.h"

namespace sbaslam::map {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

// Local mapping holds the lock through a long edit made of short steps and yields between them; a
// tracker that asks for the lock meanwhile must get it before the edit ends.
TEST(MapLock, WaitingTrackerGetsTheLockAtTheMappersNextYield) {
  Map map;
  std::atomic<bool> mapper_holds_lock{false};
  std::atomic<bool> tracker_had_lock{false};
  bool tracker_had_lock_during_edit = false;

  std::thread mapper([&] {
    std::unique_lock<std::mutex> lock(map.mutex());
    mapper_holds_lock = true;
    const auto give_up = steady_clock::now() + std::chrono::seconds(5);
    while (steady_clock::now() < give_up) {
      std::this_thread::sleep_for(milliseconds(1));  // one step of the edit, under the lock
      map.yield_to_tracking(lock);
      ASSERT_TRUE(lock.owns_lock());
      if (tracker_had_lock) {
        tracker_had_lock_during_edit = true;
        break;
      }
    }
  });
  while (!mapper_holds_lock) std::this_thread::yield();
  {
    std::unique_lock<std::mutex> lock = map.lock_for_tracking();
    EXPECT_TRUE(lock.owns_lock());
    tracker_had_lock = true;
  }
  mapper.join();
  EXPECT_TRUE(tracker_had_lock_during_edit);
}

// Without a waiting tracker, yielding keeps the lock.
TEST(MapLock, YieldWithoutAWaitingTrackerKeepsTheLock) {
  Map map;
  std::unique_lock<std::mutex> lock(map.mutex());
  map.yield_to_tracking(lock);
  EXPECT_TRUE(lock.owns_lock());
}

}  // namespace
}  // namespace sbaslam::map
