#include "sbaslam/optimize/reprojection_cost.h"

#include <gtest/gtest.h>

#include "helper/pose_steps.h"
#include "helper/synthetic_views.h"
#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

// Central differences of the residual along the manifold's tangent (pose) and in R^3 (point).
void numeric_jacobians(const RectifiedCamera& cam, const PixelObservation& obs,
                       const PoseParameters& pose, const Vec3& point, Eigen::MatrixXd& J_pose,
                       Eigen::MatrixXd& J_point) {
  const int n = obs.residual_size();
  const double h = 1e-6;
  J_pose.resize(n, 6);
  J_point.resize(n, 3);
  for (int k = 0; k < 6; ++k) {
    const auto [plus, minus] = test::tangent_steps(pose, k, h);
    double rp[3], rm[3];
    evaluate_reprojection(cam, obs, plus.data(), point.data(), rp, nullptr, nullptr);
    evaluate_reprojection(cam, obs, minus.data(), point.data(), rm, nullptr, nullptr);
    for (int r = 0; r < n; ++r) J_pose(r, k) = (rp[r] - rm[r]) / (2 * h);
  }
  for (int k = 0; k < 3; ++k) {
    Vec3 plus = point, minus = point;
    plus[k] += h;
    minus[k] -= h;
    double rp[3], rm[3];
    evaluate_reprojection(cam, obs, pose.data(), plus.data(), rp, nullptr, nullptr);
    evaluate_reprojection(cam, obs, pose.data(), minus.data(), rm, nullptr, nullptr);
    for (int r = 0; r < n; ++r) J_point(r, k) = (rp[r] - rm[r]) / (2 * h);
  }
}

TEST(ReprojectionCost, AnalyticJacobiansMatchNumericDifferentiation) {
  const RectifiedCamera cam = test::kitti_like_camera();
  const SE3 T_cw(SO3::exp(Vec3(0.1, -0.2, 0.05)), Vec3(0.3, 0.1, -0.4));
  const PoseParameters pose = to_parameters(T_cw);
  for (bool stereo : {false, true}) {
    const Vec3 point(1.5, -0.7, 9.0);
    PixelObservation obs = test::project(cam, T_cw, point, stereo);
    obs.u += 1.3;  // a non-zero residual
    obs.inv_sigma2 = 1.0 / 1.44;
    obs.weight = 2.5;
    const int n = obs.residual_size();
    double residual[3], J_pose[21], J_point[9];
    ASSERT_TRUE(
        evaluate_reprojection(cam, obs, pose.data(), point.data(), residual, J_pose, J_point));
    EXPECT_NEAR(residual[0], std::sqrt(2.5 / 1.44) * 1.3, 1e-9);
    Eigen::MatrixXd N_pose, N_point;
    numeric_jacobians(cam, obs, pose, point, N_pose, N_point);
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < 6; ++c)
        EXPECT_NEAR(J_pose[7 * r + c], N_pose(r, c), 1e-4 * (1.0 + std::abs(N_pose(r, c))))
            << "pose r" << r << " c" << c << " stereo " << stereo;
      EXPECT_EQ(J_pose[7 * r + 6], 0.0);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(J_point[3 * r + c], N_point(r, c), 1e-4 * (1.0 + std::abs(N_point(r, c))));
    }
  }
}

// The split-pose factor of local and global BA gives the same residual and, column for column,
// the same Jacobian as the 7-double pose; a monocular observation's padding row is all zero.
TEST(ReprojectionCost, SplitPoseFactorAgreesWithTheSevenDoublePose) {
  const RectifiedCamera cam = test::kitti_like_camera();
  const SE3 T_cw(SO3::exp(Vec3(0.1, -0.2, 0.05)), Vec3(0.3, 0.1, -0.4));
  PoseParameters pose = to_parameters(T_cw);
  Vec3 point(1.5, -0.7, 9.0);
  for (bool stereo : {false, true}) {
    PixelObservation obs = test::project(cam, T_cw, point, stereo);
    obs.v -= 0.8;
    obs.weight = 3.0;
    double expected[3], J_expected[21], J_point_expected[9];
    evaluate_reprojection(cam, obs, pose.data(), point.data(), expected, J_expected,
                          J_point_expected);
    const SplitPoseReprojectionFactor factor(cam, obs);
    const ceres::CostFunction* cost = &factor;
    ASSERT_EQ(cost->num_residuals(), 3);
    double residual[3], J_rotation[12], J_translation[9], J_point[9];
    const double* parameters[3] = {rotation_block(pose), translation_block(pose), point.data()};
    double* jacobians[3] = {J_rotation, J_translation, J_point};
    ASSERT_TRUE(cost->Evaluate(parameters, residual, jacobians));
    const int n = obs.residual_size();
    for (int r = 0; r < 3; ++r) {
      const bool padding = r >= n;
      EXPECT_EQ(residual[r], padding ? 0.0 : expected[r]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(J_rotation[4 * r + c], padding ? 0.0 : J_expected[7 * r + c]);
        EXPECT_EQ(J_translation[3 * r + c], padding ? 0.0 : J_expected[7 * r + 3 + c]);
        EXPECT_EQ(J_point[3 * r + c], padding ? 0.0 : J_point_expected[3 * r + c]);
      }
      EXPECT_EQ(J_rotation[4 * r + 3], 0.0);
    }
  }
}

// The rotation block's manifold moves the quaternion exactly as the pose manifold does.
TEST(ReprojectionCost, RotationManifoldMatchesThePoseManifold) {
  const PoseParameters pose = to_parameters(SE3(SO3::exp(Vec3(0.3, 0.1, -0.2)), Vec3(1, 2, 3)));
  const double delta[6] = {0.01, -0.02, 0.03, 0.0, 0.0, 0.0};
  PoseParameters moved, rotated = pose;
  PoseManifold().Plus(pose.data(), delta, moved.data());
  const RotationManifold rotation;
  rotation.Plus(pose.data(), delta, rotated.data());
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(rotated[i], moved[i], 1e-15);
  double back[3];
  rotation.Minus(rotated.data(), pose.data(), back);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], delta[i], 1e-12);
}

TEST(ReprojectionCost, PointBehindCameraIsReportedAndHasZeroResidual) {
  const RectifiedCamera cam = test::kitti_like_camera();
  const PoseParameters pose = to_parameters(SE3());
  const Vec3 behind(0.0, 0.0, -5.0);
  PixelObservation obs;
  obs.u = 600;
  obs.v = 180;
  double residual[2];
  EXPECT_FALSE(
      evaluate_reprojection(cam, obs, pose.data(), behind.data(), residual, nullptr, nullptr));
  EXPECT_EQ(residual[0], 0.0);
  EXPECT_FALSE(check_reprojection(cam, pose.data(), behind.data(), obs).in_front);
}

TEST(ReprojectionCost, ChiSquareIsUnweighted) {
  const RectifiedCamera cam = test::kitti_like_camera();
  const PoseParameters pose = to_parameters(SE3());
  const Vec3 point(0.0, 0.0, 10.0);
  PixelObservation obs = test::project(cam, SE3(), point, false);
  obs.u += 2.0;
  obs.inv_sigma2 = 0.5;
  obs.weight = 10.0;
  EXPECT_NEAR(check_reprojection(cam, pose.data(), point.data(), obs).chi2, 4.0 * 0.5, 1e-9);
}

}  // namespace
}  // namespace sbaslam::optimize
