#include "sbaslam/geometry/motion_refinement.h"

#include <gtest/gtest.h>

#include "geometry/two_view_scene.h"

namespace sbaslam::geometry {
namespace {

RelativeMotion truth_of(const test::TwoViewScene& s) {
  RelativeMotion m;
  m.R21 = s.R21;
  m.t21 = s.t21.normalized();
  return m;
}

// A wrong match on the epipolar line of p1 but at negative depth, 1.5 px off the line: it passes
// the Sampson gate (1.96 px) and implies a ~150 px "parallax" the wrong way.
Vec2 match_behind_the_camera(const test::TwoViewScene& s, const Vec2& p1) {
  const Vec3 ray((p1.x() - s.k.cx) / s.k.fx, (p1.y() - s.k.cy) / s.k.fy, 1.0);
  auto image_at_depth = [&](double z1) {
    return test::project_px(s.k, s.R21 * (z1 * ray) + s.t21);
  };
  const Vec2 on_line = image_at_depth(-2.0);
  const Vec2 along = (image_at_depth(-2.01) - on_line).normalized();
  return on_line + 1.5 * Vec2(-along.y(), along.x());
}

TEST(RefineMotion, AMatchBehindTheCameraDoesNotPullTheDirection) {
  test::SceneSpec spec;
  spec.noise_px = 0.5;
  spec.outlier_fraction = 0.0;
  const auto s = test::make_scene(spec);
  Correspondences clean = test::correspondences_of(s);
  const RelativeMotion without = refine_motion(truth_of(s), clean, s.k);

  Correspondences planted = clean;
  const Vec2 p1(40.0, 440.0);  // a corner: the most leverage on the direction
  const Vec2 p2 = match_behind_the_camera(s, p1);
  ASSERT_TRUE(test::in_image(p2));
  ASSERT_LT(sampson_distance(truth_of(s), s.k, p1, p2), 1.96);
  planted.add(p1, p2);
  const RelativeMotion with = refine_motion(truth_of(s), planted, s.k);
  // Measured without the depth test: 0.21 degrees apart.
  EXPECT_LT(direction_angle_deg(with.t21, without.t21), 0.01);
}

TEST(RefinePlaneMotion, NoiseFreeFloorConvergesToTheTruthFromAPerturbedCandidate) {
  test::SceneSpec spec;
  spec.planar = true;  // the floor y = 1 below camera 1
  spec.noise_px = 0.0;
  spec.outlier_fraction = 0.0;
  spec.t21 = Vec3(-1.0, 0.0, 0.0);
  const auto s = test::make_scene(spec);
  const Vec3 n(0.0, 1.0, 0.0);
  // A candidate as decompose_homography gives it: an exact decomposition of a homography fitted
  // to noisy points, here about 0.03 degrees of rotation and 0.15 of direction and normal away
  // (up to 2 px of transfer error: within the gate).
  RelativeMotion candidate;
  candidate.R21 = SO3::exp(Vec3(0.0003, -0.0003, 0.0003)).matrix() * s.R21;
  candidate.t21 = SO3::exp(Vec3(0.0, 0.0018, 0.0018)).matrix() * s.t21.normalized();
  candidate.normal = SO3::exp(Vec3(0.0018, 0.0, 0.0018)).matrix() * n;
  const Mat3 fitted =
      test::plane_homography(s.k, candidate.R21, candidate.t21, candidate.normal, 1.0);
  const RelativeMotion refined =
      refine_plane_motion(candidate, fitted, test::correspondences_of(s), s.k);
  EXPECT_LT(rotation_angle_deg(refined.R21, s.R21), 1e-5);
  EXPECT_LT(direction_angle_deg(refined.t21, s.t21), 1e-5);
  EXPECT_NEAR(refined.t21.norm(), 1.0, 1e-12);
  EXPECT_LT(direction_angle_deg(refined.normal, n), 1e-5);
  EXPECT_GT(rotation_angle_deg(candidate.R21, s.R21), 0.025);
  EXPECT_GT(direction_angle_deg(candidate.t21, s.t21), 0.1);
}

TEST(RefinePlaneMotion, TooFewCorrespondencesReturnTheCandidate) {
  RelativeMotion candidate;
  candidate.t21 = Vec3(1.0, 0.0, 0.0);
  candidate.normal = Vec3(0.0, 0.0, 1.0);
  Correspondences c;
  for (int i = 0; i < 5; ++i) c.add(Vec2(100.0 + 10 * i, 200.0), Vec2(90.0 + 10 * i, 200.0));
  const RelativeMotion out =
      refine_plane_motion(candidate, Mat3::Identity(), c, test::vga_intrinsics());
  EXPECT_EQ(out.R21, candidate.R21);
  EXPECT_EQ(out.t21, candidate.t21);
}

}  // namespace
}  // namespace sbaslam::geometry
