#include "sbaslam/loop/loop_gate.h"

#include <gtest/gtest.h>

#include <memory>

#include "helper/camera_rig.h"

namespace sbaslam {
namespace {

// Keyframes 5 m apart along x: a loaded map's drive (ids 0-9, x = 0..45 m), then this run's drive
// (ids 10-19), which relocalised at the loaded map's start and drove the same street again.
struct TwoDrives {
  map::CameraRig rig = test::vga_mono_rig();
  map::Map map;
  std::vector<map::KeyFrame*> keyframes;

  TwoDrives() {
    auto m = std::make_shared<map::Measurements>();
    const std::size_t map_id = map.new_map_id();
    for (int i = 0; i < 20; ++i) {
      const double x = 5.0 * (i % 10);
      map::KeyFrame* kf = map.create_keyframe(static_cast<std::size_t>(i), 0.1 * (i % 10),
                                              SE3(SO3(), Vec3(-x, 0.0, 0.0)), m, &rig, map_id);
      if (i == 0) kf->set_origin();
      if (i > 0) kf->change_parent(keyframes.back());
      keyframes.push_back(kf);
    }
  }
};

TEST(LoopGate, PathWithinOneDriveFollowsTheKeyframesInOrder) {
  TwoDrives d;
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[2], *d.keyframes[7], 10), 25.0);
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[17], *d.keyframes[12], 10), 25.0);
  // Without a loaded map the ids are one drive: 2 -> 9 (35 m), a jump back (45 m), 10 -> 15 (25 m).
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[2], *d.keyframes[15]), 105.0);
}

TEST(LoopGate, PathFromALoadedKeyframeGoesThroughWhereThisRunJoinedTheMap) {
  TwoDrives d;
  // Loaded keyframe 2 (x = 10) back to keyframe 0, where this run began (10 m), then this run's
  // keyframes 10 -> 15 (25 m).
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[2], *d.keyframes[15], 10), 35.0);
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[15], *d.keyframes[2], 10), 35.0);
  // The first keyframe of this run culled: the run joined the map where its next one is.
  d.keyframes[10]->set_bad();
  EXPECT_DOUBLE_EQ(loop::driven_path_length(d.map, *d.keyframes[2], *d.keyframes[15], 10), 25.0);
}

TEST(LoopGate, LossBeforeAMapCountsOnlyThisRunsKeyframes) {
  TwoDrives d;
  // Keyframe 15 taken as a new map's root: this run's keyframes 10-14 went 5 m per 0.1 s.
  const loop::Loss loss = loop::loss_before(d.map, *d.keyframes[15], 10);
  EXPECT_NEAR(loss.speed, 50.0, 1e-9);
  EXPECT_NEAR(loss.seconds, 0.1, 1e-9);
  // Root 10, this run's first keyframe: nothing of this run came before it. Counted with the
  // loaded keyframes, the loaded drive's speed would pass for this run's.
  const loop::Loss first = loop::loss_before(d.map, *d.keyframes[10], 10);
  EXPECT_DOUBLE_EQ(first.speed, 0.0);
  EXPECT_DOUBLE_EQ(first.seconds, 0.0);
  EXPECT_NEAR(loop::loss_before(d.map, *d.keyframes[10]).speed, 50.0, 1e-9);
}

TEST(LoopGate, AMapThisRunStartedBesideALoadedOneHasNoKnownPlace) {
  TwoDrives d;
  // This run's first keyframe rooted a map of its own (its first frame did not relocalise in the
  // loaded map): it started where no pose was known, and a merge may move it any distance.
  EXPECT_FALSE(loop::loss_before(d.map, *d.keyframes[10], 10).anchored);
  // A map started after a loss later in the run began at the last known pose.
  EXPECT_TRUE(loop::loss_before(d.map, *d.keyframes[15], 10).anchored);
  // Without a loaded map the first keyframe roots the oldest map, which never moves; every later
  // root follows a loss.
  EXPECT_TRUE(loop::loss_before(d.map, *d.keyframes[0]).anchored);
  EXPECT_TRUE(loop::loss_before(d.map, *d.keyframes[10]).anchored);
}

}  // namespace
}  // namespace sbaslam
