#include "sbaslam/geometry/relative_pose.h"

#include <gtest/gtest.h>

#include "geometry/two_view_scene.h"
#include "sbaslam/geometry/motion_check.h"

namespace sbaslam::geometry {
namespace {

bool contains(const std::vector<RelativeMotion>& motions, const Mat3& R, const Vec3& t) {
  for (const RelativeMotion& m : motions)
    if (rotation_angle_deg(m.R21, R) < 1e-4 && direction_angle_deg(m.t21, t) < 1e-4) return true;
  return false;
}

TEST(DecomposeHomography, EightCandidatesIncludeTheTruth) {
  const Mat3 R = SO3::exp(Vec3(0.05, -0.1, 0.02)).matrix();
  const Vec3 t(0.4, -0.1, 0.2), n = Vec3(0.1, -0.2, 1.0).normalized();
  const auto d = decompose_homography(test::plane_homography(test::vga_intrinsics(), R, t, n, 5.0),
                                      test::vga_intrinsics());
  EXPECT_FALSE(d.pure_rotation);
  EXPECT_EQ(d.motions.size(), 8u);
  EXPECT_TRUE(contains(d.motions, R, t));
  for (const RelativeMotion& m : d.motions) {
    EXPECT_NEAR(m.R21.determinant(), 1.0, 1e-9);
    EXPECT_NEAR(m.t21.norm(), 1.0, 1e-9);
  }
}

TEST(DecomposeHomography, MotionAlongThePlaneNormalIsNotRefused) {
  // Walking straight at a wall: two singular values coincide, which ORB-SLAM refuses outright.
  const Mat3 R = SO3::exp(Vec3(0.0, 0.0, 0.03)).matrix();
  const Vec3 n(0.0, 0.0, 1.0), t = -0.3 * n;
  const auto d = decompose_homography(test::plane_homography(test::vga_intrinsics(), R, t, n, 4.0),
                                      test::vga_intrinsics());
  EXPECT_FALSE(d.pure_rotation);
  EXPECT_LT(d.motions.size(), 8u);  // duplicates dropped
  EXPECT_TRUE(contains(d.motions, R, t));
}

TEST(DecomposeHomography, PureRotationIsFlagged) {
  const Mat3 R = SO3::exp(Vec3(0.1, 0.05, -0.02)).matrix();
  const Mat3 K = camera_matrix(test::vga_intrinsics());
  const auto d = decompose_homography(3.0 * K * R * K.inverse(), test::vga_intrinsics());
  EXPECT_TRUE(d.pure_rotation);
  EXPECT_TRUE(d.motions.empty());
}

TEST(DecomposeEssential, FourCandidatesIncludeTheTruth) {
  const Mat3 R = SO3::exp(Vec3(-0.2, 0.1, 0.05)).matrix();
  const Vec3 t = Vec3(0.3, 0.2, -0.9).normalized();
  const Mat3 E = hat(t) * R;
  const auto motions = decompose_essential(E);
  ASSERT_EQ(motions.size(), 4u);
  EXPECT_TRUE(contains(motions, R, t));
  // Via F = K^-T E K^-1 and back.
  const Mat3 K = camera_matrix(test::vga_intrinsics());
  const Mat3 F = K.inverse().transpose() * E * K.inverse();
  EXPECT_TRUE(
      contains(decompose_essential(essential_from_fundamental(F, test::vga_intrinsics())), R, t));
}

TEST(TriangulateLinear, RecoversThePointAndRejectsInfinity) {
  const Mat3 R = SO3::exp(Vec3(0.0, 0.1, 0.0)).matrix();
  const Vec3 t(-0.5, 0.0, 0.0), X(0.3, -0.4, 6.0);
  const Vec3 X2 = R * X + t;
  const auto p = triangulate_linear(X.hnormalized(), X2.hnormalized(), R, t);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR((*p - X).norm(), 0.0, 1e-9);
  // Parallel rays (a direction seen from both centres): the point is at infinity.
  EXPECT_FALSE(triangulate_linear(X.hnormalized(), (R * X).hnormalized(), R, t));
}

TEST(CheckMotion, TrueMotionIsSupportedAndItsMirrorIsNot) {
  test::SceneSpec spec;
  spec.outlier_fraction = 0.0;
  spec.noise_px = 0.5;
  const auto s = test::make_scene(spec);
  Correspondences c;
  for (std::size_t i = 0; i < s.keypoints1.size(); ++i)
    c.add(Vec2(s.keypoints1[i].x, s.keypoints1[i].y), Vec2(s.keypoints2[i].x, s.keypoints2[i].y));
  const std::vector<char> all(c.size(), 1);
  const Vec3 t = s.t21.normalized();
  const MotionSupport truth = check_motion({s.R21, t, Vec3::Zero()}, c, all, s.k);
  EXPECT_GT(truth.good, 0.95 * c.size());
  EXPECT_EQ(truth.triangulated, truth.good);  // 0.6 m baseline at 4-10 m: all have parallax
  EXPECT_GT(truth.parallax_deg, 3.0);
  // Points come out at the scale |t| = 1: compare with the truth scaled by 1 / |t21|.
  const double scale = 1.0 / s.t21.norm();
  int close = 0;
  for (int i = 0; i < c.size(); ++i)
    close += truth.valid[i] &&
             (truth.points[i] - scale * s.points1[i]).norm() < 0.05 * (scale * s.points1[i]).norm();
  EXPECT_GT(close, 0.9 * c.size());
  const MotionSupport mirrored = check_motion({s.R21, -t, Vec3::Zero()}, c, all, s.k);
  EXPECT_EQ(mirrored.triangulated, 0);
}

}  // namespace
}  // namespace sbaslam::geometry
