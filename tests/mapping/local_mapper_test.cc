// The mapping thread's scheduling around feature extraction (LocalMapper::yield_cores).

#include "sbaslam/mapping/local_mapper.h"

#include <gtest/gtest.h>
#include <sched.h>

namespace sbaslam::mapping {
namespace {

TEST(LocalMapper, MappingThreadIsIdlePolicyOnlyWhileTrackingExtracts) {
  map::Map map;
  const map::CameraRig rig;
  LocalMapper mapper(map, rig, LocalMapperOptions{});
  EXPECT_EQ(mapper.thread_policy(), -1);  // no thread yet
  mapper.start();
  if (!mapper.yields_cores()) GTEST_SKIP() << "this process may not leave SCHED_IDLE";
  EXPECT_EQ(mapper.thread_policy(), SCHED_OTHER);
  mapper.yield_cores(true);
  EXPECT_EQ(mapper.thread_policy(), SCHED_IDLE);
  mapper.yield_cores(false);
  EXPECT_EQ(mapper.thread_policy(), SCHED_OTHER);
  mapper.stop();
}

TEST(LocalMapper, SwitchedOffYieldingLeavesThePolicyAlone) {
  map::Map map;
  const map::CameraRig rig;
  LocalMapperOptions options;
  options.yield_cores_to_extraction = false;
  LocalMapper mapper(map, rig, options);
  mapper.start();
  EXPECT_FALSE(mapper.yields_cores());
  mapper.yield_cores(true);
  EXPECT_EQ(mapper.thread_policy(), SCHED_OTHER);
  mapper.stop();
}

}  // namespace
}  // namespace sbaslam::mapping
