#include "sbaslam/tracking/pose_prior.h"

#include <gtest/gtest.h>

#include <memory>

#include "helper/camera_rig.h"
#include "sbaslam/map/map.h"

namespace sbaslam::tracking {
namespace {

// T_cw of a camera whose centre is `centre` (any orientation: the prior looks at centres only).
SE3 camera_at(const Vec3& centre, const SO3& R_cw = SO3()) {
  return SE3(R_cw, -(R_cw * centre));
}

TEST(PosePrior, WithinComparesCameraCentresNotTranslations) {
  const PosePrior prior{Vec3(10.0, 0.0, 5.0), 2.0};
  const SO3 turned = SO3::exp(Vec3(0.0, 1.2, 0.0));
  EXPECT_TRUE(within(prior, camera_at(Vec3(11.5, 0.0, 5.0), turned)));
  EXPECT_TRUE(within(prior, camera_at(Vec3(10.0, 2.0, 5.0))));  // on the radius
  EXPECT_FALSE(within(prior, camera_at(Vec3(10.0, 0.0, 7.5), turned)));
  // T_cw's translation at the prior's centre is not a camera centre there (the centre is -R^T t).
  EXPECT_FALSE(within(prior, SE3(turned, Vec3(10.0, 0.0, 5.0))));
}

TEST(PosePrior, KeepNearestKeepsTheCandidatesClosestToTheCentreNearestFirst) {
  const map::CameraRig rig = test::vga_mono_rig();
  map::Map map;
  const std::size_t map_id = map.new_map_id();
  auto m = std::make_shared<map::Measurements>();
  std::vector<map::KeyFrame*> candidates;
  for (const double z : {40.0, 3.0, -20.0, 8.0, 1.0})
    candidates.push_back(
        map.create_keyframe(candidates.size(), 0.0, camera_at(Vec3(0.0, 0.0, z)), m, &rig, map_id));
  map::KeyFrame* at_40 = candidates[0];
  map::KeyFrame* at_3 = candidates[1];
  map::KeyFrame* at_1 = candidates[4];
  keep_nearest(candidates, PosePrior{Vec3(0.0, 0.0, 2.0), 1.0}, 3);
  ASSERT_EQ(candidates.size(), 3u);
  // 1 and 3 are both 1 m away: the order they came in.
  EXPECT_EQ(candidates[0], at_3);
  EXPECT_EQ(candidates[1], at_1);
  EXPECT_EQ(candidates[2]->T_wc().translation().z(), 8.0);
  keep_nearest(candidates, PosePrior{Vec3(0.0, 0.0, 50.0), 1.0}, 5);
  EXPECT_EQ(candidates.size(), 3u);
  EXPECT_NE(candidates[0], at_40);  // dropped before
}

}  // namespace
}  // namespace sbaslam::tracking
