// The mapping thread's scheduling around feature extraction (LocalMapper::yield_cores), and the
// options its local BA runs with.

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

TEST(LocalMapper, StereoLocalBundleAdjustmentEndsAtTheStereoTolerance) {
  map::Map map;
  LocalMapperOptions options;
  options.bundle_adjustment.function_tolerance = 1e-6;
  options.bundle_adjustment.refine_iterations = 7;
  options.stereo_ba_function_tolerance = 3e-2;
  map::CameraRig mono;
  mono.stereo = false;
  map::CameraRig stereo;
  stereo.stereo = true;
  const LocalMapper mono_mapper(map, mono, options);
  const LocalMapper stereo_mapper(map, stereo, options);
  EXPECT_EQ(mono_mapper.local_bundle_adjustment_options().function_tolerance, 1e-6);
  EXPECT_EQ(stereo_mapper.local_bundle_adjustment_options().function_tolerance, 3e-2);
  EXPECT_EQ(stereo_mapper.local_bundle_adjustment_options().refine_iterations, 7);
}

}  // namespace
}  // namespace sbaslam::mapping
