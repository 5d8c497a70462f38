// The weights a map BA is built with (Saliency.map_ba_depth): by default the ones stored with the
// keypoints; with point-depth weighting, recomputed from each keypoint's S_init and its point's
// depth in the keyframe, so that a nearer point of the same saliency weighs more.

#include "sbaslam/optimize/map_bundle_adjustment.h"

#include <gtest/gtest.h>

#include "helper/circular_map.h"
#include "sbaslam/saliency/observation_weight.h"

namespace sbaslam::optimize {
namespace {

constexpr float kStoredWeight = 3.0f;

// Every keypoint stores weight 3; the keyframes in `with_s_init` also keep S_init = 1.
std::unique_ptr<test::CircularMap> map_with_saliency(const std::vector<std::size_t>& with_s_init) {
  test::CircularMapOptions options;
  options.keyframes = 12;
  options.points = 1200;
  auto c = test::make_circular_map(options);
  for (map::KeyFrame* kf : c->map.keyframes()) {
    auto m = std::const_pointer_cast<map::Measurements>(kf->measurements_ptr());
    m->weights.assign(m->size(), kStoredWeight);
  }
  for (std::size_t k : with_s_init) {
    auto m = std::const_pointer_cast<map::Measurements>(c->keyframes[k]->measurements_ptr());
    m->s_init.assign(m->size(), 1.0f);
  }
  return c;
}

MapBaWeighting point_depth_weighting() {
  SaliencySettings saliency;
  saliency.weight_a = 256.0;
  saliency.weight_b = 1.0;
  return {saliency};
}

double depth_in(const map::KeyFrame& kf, const Vec3& position) {
  return (kf.T_cw() * position).z();
}

TEST(MapBaWeighting, NearerPointsOfEqualSaliencyWeighMoreWithPointDepth) {
  auto c = map_with_saliency({6});
  map::KeyFrame* kf = c->keyframes[6];
  const MapBaWeighting weighting = point_depth_weighting();
  const MapBundleAdjustment ba = build_local_bundle_adjustment(kf, c->rig, 5, weighting);
  const double near = kf->scene_depth_quantile(0.5);
  ASSERT_GT(near, 0.0);
  EXPECT_EQ(point_depth_near(*kf, c->rig, *weighting.point_depth), near);
  int nearer = 0, farther = 0;
  for (std::size_t i = 0; i < ba.problem.observations.size(); ++i) {
    const BaObservation& o = ba.problem.observations[i];
    const map::KeyFrame* observer = ba.keyframes[static_cast<std::size_t>(o.keyframe)];
    if (observer != kf) {
      EXPECT_EQ(o.pixel.weight, kStoredWeight) << "a keyframe without S_init keeps its weights";
      continue;
    }
    const double z = depth_in(*kf, ba.points[static_cast<std::size_t>(o.point)]->position());
    EXPECT_FLOAT_EQ(static_cast<float>(o.pixel.weight),
                    saliency::point_depth_weight(1.0f, z, near, *weighting.point_depth));
    if (z <= near) {
      EXPECT_FLOAT_EQ(static_cast<float>(o.pixel.weight), 257.0f);
      ++nearer;
    } else {
      // s = near / z, so w = 256 (near / z)^2 + 1 falls with depth.
      EXPECT_LT(o.pixel.weight, 257.0);
      EXPECT_GT(o.pixel.weight, 1.0);
      ++farther;
    }
  }
  EXPECT_GT(nearer, 50);
  EXPECT_GT(farther, 50);
}

TEST(MapBaWeighting, WithoutPointDepthEveryMapBaKeepsTheStoredWeights) {
  auto c = map_with_saliency({0, 6});
  const MapBundleAdjustment local = build_local_bundle_adjustment(c->keyframes[6], c->rig, 5);
  const MapBundleAdjustment global = build_global_bundle_adjustment(c->map, c->rig);
  ASSERT_FALSE(local.problem.observations.empty());
  ASSERT_FALSE(global.problem.observations.empty());
  for (const MapBundleAdjustment* ba : {&local, &global})
    for (const BaObservation& o : ba->problem.observations)
      EXPECT_EQ(o.pixel.weight, kStoredWeight);
}

TEST(MapBaWeighting, GlobalBaWeighsEveryKeyframeThatKeptSInit) {
  auto c = map_with_saliency({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11});
  const MapBundleAdjustment ba =
      build_global_bundle_adjustment(c->map, c->rig, point_depth_weighting());
  ASSERT_FALSE(ba.problem.observations.empty());
  for (const BaObservation& o : ba.problem.observations) {
    EXPECT_NE(o.pixel.weight, kStoredWeight);
    EXPECT_GT(o.pixel.weight, 1.0);
    EXPECT_LE(o.pixel.weight, 257.0);
  }
}

// Saliency.depth_near: set, it is the floor in every keyframe; set to 0, the keyframe's nearest
// point; unset on a stereo rig, the rig's close-point threshold.
TEST(MapBaWeighting, TheDepthFloorFollowsSaliencyDepthNear) {
  auto c = map_with_saliency({});
  const map::KeyFrame& kf = *c->keyframes[3];
  SaliencySettings saliency;
  saliency.depth_near = 7.5;
  EXPECT_EQ(point_depth_near(kf, c->rig, saliency), 7.5);
  saliency.depth_near = 0.0;
  EXPECT_EQ(point_depth_near(kf, c->rig, saliency), kf.scene_depth_quantile(0.0));
  EXPECT_LT(kf.scene_depth_quantile(0.0), kf.scene_depth_quantile(0.5));
  saliency.depth_near.reset();
  map::CameraRig stereo = c->rig;
  stereo.stereo = true;
  stereo.th_depth = 12.0;
  EXPECT_EQ(point_depth_near(kf, stereo, saliency), 12.0);
}

}  // namespace
}  // namespace sbaslam::optimize
