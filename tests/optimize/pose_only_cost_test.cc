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

// The block's squared norm is the sum of Huber costs of the weighted chi-square errors, exactly
// what a Ceres HuberLoss on one block per observation minimises.
TEST(PoseOnlyCost, SquaredNormIsTheSumOfHuberCosts) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  const double delta_mono = std::sqrt(kChi2Mono), delta_stereo = std::sqrt(kChi2Stereo);
  const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {0, 1, 2, 3, 4, 5},
                          delta_mono, delta_stereo);
  std::vector<double> residuals(static_cast<std::size_t>(cost.num_residuals()));
  cost.evaluate(pose.data(), residuals.data(), nullptr);
  double expected = 0.0, got = 0.0;
  int linear_part = 0;
  for (std::size_t i = 0; i < scene.observations.size(); ++i) {
    const PixelObservation& obs = scene.observations[i];
    double e[3];
    evaluate_reprojection(scene.cam, obs, pose.data(), scene.points[i].data(), e, nullptr, nullptr);
    double s = 0.0;
    for (int r = 0; r < obs.residual_size(); ++r) s += e[r] * e[r];
    const double delta = obs.is_stereo() ? delta_stereo : delta_mono;
    if (s > delta * delta) ++linear_part;
    expected += huber_rho(s, delta);
  }
  for (double r : residuals) got += r * r;
  EXPECT_GE(linear_part, 3);  // the scene exercises both parts of the kernel
  EXPECT_NEAR(got, expected, 1e-9 * expected);
  EXPECT_NEAR(cost.cost(pose.data()), 0.5 * expected, 1e-9 * expected);
}

// Analytic Jacobian against central differences along the pose manifold, with the kernel on and
// off, and only a subset of observations active.
TEST(PoseOnlyCost, JacobianMatchesNumericDifferentiation) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  for (double delta : {std::sqrt(kChi2Mono), 0.0}) {
    const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {1, 2, 3, 4}, delta,
                            delta);
    const int n = cost.num_residuals();
    ASSERT_EQ(n, 3 + 2 + 3 + 2);
    std::vector<double> residuals(static_cast<std::size_t>(n)), J(static_cast<std::size_t>(6 * n));
    cost.evaluate(pose.data(), residuals.data(), J.data());
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      const auto [plus, minus] = test::tangent_steps(pose, k, h);
      std::vector<double> rp(residuals.size()), rm(residuals.size());
      cost.evaluate(plus.data(), rp.data(), nullptr);
      cost.evaluate(minus.data(), rm.data(), nullptr);
      for (int r = 0; r < n; ++r) {
        const double numeric = (rp[r] - rm[r]) / (2 * h);
        EXPECT_NEAR(J[6 * r + k], numeric, 1e-5 * (1.0 + std::abs(numeric)))
            << "row " << r << " column " << k << " kernel " << delta;
      }
    }
  }
}

// The solver's one-pass sums are the normal equations of the rows above: cost = |r|^2 / 2,
// H = J^T J, g = J^T r.
TEST(PoseOnlyCost, NormalEquationsAreThoseOfTheRows) {
  const Scene scene;
  const PoseParameters pose = to_parameters(scene.T_cw);
  const PoseOnlyCost cost(scene.cam, scene.observations, scene.points, {0, 2, 3, 5},
                          std::sqrt(kChi2Mono), std::sqrt(kChi2Stereo));
  const int n = cost.num_residuals();
  Eigen::VectorXd r(n);
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> J(n, 6);
  cost.evaluate(pose.data(), r.data(), J.data());
  const PoseNormalEquations ne = cost.normal_equations(pose.data());
  EXPECT_NEAR(ne.cost, 0.5 * r.squaredNorm(), 1e-12 * r.squaredNorm());
  const Mat66 H = J.transpose() * J;
  const Vec6 g = J.transpose() * r;
  EXPECT_LT((ne.H - H).norm(), 1e-10 * H.norm());
  EXPECT_LT((ne.g - g).norm(), 1e-10 * g.norm());
  EXPECT_GT(g.norm(), 0.0);  // the scene is off its optimum, so the test sees a real gradient
}

}  // namespace
}  // namespace sbaslam::optimize
