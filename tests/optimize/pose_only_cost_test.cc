#include "sbaslam/optimize/pose_only_cost.h"

#include <gtest/gtest.h>

#include "helper/pose_steps.h"
#include "helper/synthetic_views.h"
#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

// Observations of a few points, some far off (inside the Huber kernel's linear part), mono and
// stereo, with salient weights.
struct Scene {
  RectifiedCamera cam = test::kitti_like_camera();
  SE3 T_cw{SO3::exp(Vec3(0.1, -0.2, 0.05)), Vec3(0.3, 0.1, -0.4)};
  std::vector<Vec3> points;
  std::vector<PixelObservation> observations;

  Scene() {
    const double offsets[] = {0.4, 1.0, 3.5, 12.0, -7.0, 0.0};
    for (int i = 0; i < 6; ++i) {
      const Vec3 p(-2.0 + 0.8 * i, 0.5 - 0.3 * i, 6.0 + 2.0 * i);
      PixelObservation obs = test::project(cam, T_cw, p, i % 2 == 0);
      obs.u += offsets[i];
      obs.v -= 0.5 * offsets[i];
      obs.inv_sigma2 = 1.0 / (1.2 * (1 + i % 3));
      obs.weight = 1.0 + i;
      points.push_back(p);
      observations.push_back(obs);
    }
  }
};

// The residual and its tangent Jacobian (n x 6) of one observation, as the cost sees them.
void residual_of(const Scene& scene, std::size_t i, const PoseParameters& pose, Eigen::Vector3d& e,
                 Eigen::Matrix<double, 3, 6>& J) {
  double r[3], jac[21];
  evaluate_reprojection(scene.cam, scene.observations[i], pose.data(), scene.points[i].data(), r,
                        jac, nullptr);
  const int n = scene.observations[i].residual_size();
  e.setZero();
  J.setZero();
  for (int row = 0; row < n; ++row) {
    e[row] = r[row];
    for (int c = 0; c < 6; ++c) J(row, c) = jac[7 * row + c];
  }
}

// The cost is the sum of Huber costs of the weighted chi-square errors, exactly what a Ceres
// HuberLoss on one block per observation minimises.
TEST(PoseOnlyCost, CostIsTheSumOfHuberCosts) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  const double delta_mono = std::sqrt(kChi2Mono), delta_stereo = std::sqrt(kChi2Stereo);
  const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {0, 1, 2, 3, 4, 5},
                          delta_mono, delta_stereo);
  double expected = 0.0;
  int linear_part = 0;
  for (std::size_t i = 0; i < scene.observations.size(); ++i) {
    Eigen::Vector3d e;
    Eigen::Matrix<double, 3, 6> J;
    residual_of(scene, i, pose, e, J);
    const double delta = scene.observations[i].is_stereo() ? delta_stereo : delta_mono;
    if (e.squaredNorm() > delta * delta) ++linear_part;
    expected += huber_rho(e.squaredNorm(), delta);
  }
  EXPECT_GE(linear_part, 3);  // the scene exercises both parts of the kernel
  EXPECT_NEAR(cost.normal_equations(pose.data()).cost, 0.5 * expected, 1e-9 * expected);
}

// g against central differences of the cost along the pose manifold, with the kernel on and off,
// and only a subset of observations active.
TEST(PoseOnlyCost, GradientMatchesNumericDifferentiation) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  for (double delta : {std::sqrt(kChi2Mono), 0.0}) {
    const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {1, 2, 3, 4}, delta,
                            delta);
    const Vec6 g = cost.normal_equations(pose.data()).g;
    EXPECT_GT(g.norm(), 0.0);  // the scene is off its optimum, so the test sees a real gradient
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      const auto [plus, minus] = test::tangent_steps(pose, k, h);
      const double numeric =
          (cost.normal_equations(plus.data()).cost - cost.normal_equations(minus.data()).cost) /
          (2 * h);
      EXPECT_NEAR(g[k], numeric, 1e-5 * (1.0 + std::abs(numeric)))
          << "column " << k << " kernel " << delta;
    }
  }
}

// Without a kernel, H is Gauss-Newton's sum of J^T J.
TEST(PoseOnlyCost, WithoutKernelHIsTheSumOfJTJ) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {0, 2, 3, 5}, 0.0, 0.0);
  Mat66 H = Mat66::Zero();
  for (std::size_t i : {0, 2, 3, 5}) {
    Eigen::Vector3d e;
    Eigen::Matrix<double, 3, 6> J;
    residual_of(scene, i, pose, e, J);
    H += J.transpose() * J;
  }
  EXPECT_LT((cost.normal_equations(pose.data()).H - H).norm(), 1e-10 * H.norm());
}

// In the kernel's linear part the cost grows like |e|: H has no curvature along a step that
// lengthens e, and rho'(s) = delta / |e| of Gauss-Newton's across it. (The iteratively reweighted
// H would have rho'(s) |J v|^2 along e too, and the solver's steps fell short.)
TEST(PoseOnlyCost, LinearPartHasNoCurvatureAlongTheResidual) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  const double delta = std::sqrt(kChi2Mono);
  const std::size_t far_mono = 3;  // 12 px off, weight 4
  ASSERT_FALSE(scene.observations[far_mono].is_stereo());
  const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {far_mono}, delta, delta);
  Eigen::Vector3d e;
  Eigen::Matrix<double, 3, 6> J;
  residual_of(scene, far_mono, pose, e, J);
  ASSERT_GT(e.squaredNorm(), 10.0 * delta * delta);
  const Eigen::Matrix<double, 2, 6> J2 = J.topRows<2>();
  const Eigen::Vector2d e2 = e.head<2>(), across(-e2.y(), e2.x());
  const Mat66 H = cost.normal_equations(pose.data()).H;
  // Minimum-norm tangent steps whose image moves are e and its perpendicular.
  const Eigen::Matrix<double, 6, 2> pinv = J2.transpose() * (J2 * J2.transpose()).inverse();
  const Vec6 along_step = pinv * e2, across_step = pinv * across;
  const double rho1 = delta / e2.norm();
  EXPECT_NEAR(along_step.dot(H * along_step), 0.0, 1e-9 * rho1 * e2.squaredNorm());
  EXPECT_NEAR(across_step.dot(H * across_step), rho1 * across.squaredNorm(),
              1e-9 * rho1 * across.squaredNorm());
}

}  // namespace
}  // namespace sbaslam::optimize
