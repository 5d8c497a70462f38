#include "sbaslam/eval/pose_relation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

TEST(RotationAngle, MatchesTheAxisAngleOverTheWholeRange) {
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  for (double angle : {0.0, 1e-9, 1e-4, 0.3, 1.5, 2.9, 3.1, 3.14159}) {
    const Mat3 R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_NEAR(rotation_angle(R), angle, 1e-12) << angle;
  }
  // Each branch of the largest-component choice (x, y, z, trace).
  for (int axis_index = 0; axis_index < 3; ++axis_index) {
    const Vec3 a = Vec3::Unit(axis_index);
    EXPECT_NEAR(rotation_angle(Eigen::AngleAxisd(3.0, a).toRotationMatrix()), 3.0, 1e-12);
  }
}

TEST(RotationAngle, UsesTheRawMatrixWithoutProjection) {
  // A scaled rotation, as rounding to 7 digits roughly gives. The angle comes from the raw
  // entries (trace branch: w = 1 + trace, v_z = R10 - R01), so it differs from the angle of the
  // projected rotation (0.2) by ~5e-9, which is what evo/scipy report too.
  const double eps = 1e-7;
  const Mat3 R = Eigen::AngleAxisd(0.2, Vec3::UnitZ()).toRotationMatrix() * (1.0 + eps);
  const double expected = 2.0 * std::atan2(2.0 * std::sin(0.2) * (1.0 + eps),
                                           1.0 + (1.0 + 2.0 * std::cos(0.2)) * (1.0 + eps));
  EXPECT_NEAR(rotation_angle(R), expected, 1e-15);
  EXPECT_GT(std::abs(rotation_angle(R) - 0.2), 1e-9);
}

TEST(Se3Inverse, TransposesTheRotationLikeEvo) {
  const SE3 pose(SO3::exp(Vec3(0.1, 0.2, 0.3)), Vec3(1.0, -2.0, 3.0));
  EXPECT_LT((se3_inverse(pose.matrix()) - pose.inverse().matrix()).cwiseAbs().maxCoeff(), 1e-14);
  Mat4 skewed = pose.matrix();
  skewed(0, 1) += 1e-3;  // not orthonormal any more
  const Mat4 inv = se3_inverse(skewed);
  EXPECT_EQ(Mat3(inv.topLeftCorner<3, 3>()), Mat3(skewed.topLeftCorner<3, 3>().transpose()));
  const Mat3 expected = inv.topLeftCorner<3, 3>() * skewed.topLeftCorner<3, 3>();
  EXPECT_LT((relative_se3(skewed, skewed).topLeftCorner<3, 3>() - expected).cwiseAbs().maxCoeff(),
            1e-15);
  // Not the identity that a general inverse would give.
  EXPECT_GT((expected - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(PoseError, EachRelation) {
  const Mat4 E = SE3(SO3::exp(Vec3(0.0, 0.0, 0.5)), Vec3(3.0, 4.0, 0.0)).matrix();
  EXPECT_DOUBLE_EQ(pose_error(E, PoseRelation::kTransPart), 5.0);
  EXPECT_NEAR(pose_error(E, PoseRelation::kAngleRad), 0.5, 1e-15);
  EXPECT_NEAR(pose_error(E, PoseRelation::kAngleDeg), 0.5 * 180.0 / M_PI, 1e-12);
  EXPECT_NEAR(pose_error(E, PoseRelation::kFull), (E - Mat4::Identity()).norm(), 0.0);
  EXPECT_EQ(pose_error(Mat4::Identity(), PoseRelation::kFull), 0.0);
}

TEST(PoseRelation, ParsesNamesAndRefusesOthers) {
  EXPECT_EQ(parse_pose_relation("angle_deg"), PoseRelation::kAngleDeg);
  EXPECT_EQ(pose_relation_name(parse_pose_relation("full")), "full");
  EXPECT_THROW(parse_pose_relation("rotation"), Error);
}

}  // namespace
}  // namespace sbaslam::eval
