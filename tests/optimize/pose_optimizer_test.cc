#include "sbaslam/optimize/pose_optimizer.h"

#include <gtest/gtest.h>

#include "helper/synthetic_views.h"

namespace sbaslam::optimize {
namespace {

struct PoseProblem {
  SE3 truth;
  std::vector<Vec3> points;
  std::vector<PixelObservation> observations;
};

PoseProblem make_problem(int count, bool stereo, std::mt19937& rng) {
  PoseProblem problem;
  problem.truth = SE3(SO3::exp(Vec3(0.02, -0.05, 0.01)), Vec3(0.3, -0.1, 0.5));
  const RectifiedCamera cam = test::kitti_like_camera();
  for (const Vec3& p : test::random_points(count, rng)) {
    problem.points.push_back(p);
    problem.observations.push_back(test::project(cam, problem.truth, p, stereo));
  }
  return problem;
}

SE3 perturbed(const SE3& T) {
  Vec6 delta;
  delta << 0.2, -0.1, 0.3, 0.02, -0.03, 0.01;
  return SE3::exp(delta) * T;
}

TEST(PoseOptimizer, NoiseFreeMonoAndStereoConvergeToTruth) {
  for (bool stereo : {false, true}) {
    std::mt19937 rng(1);
    const PoseProblem problem = make_problem(200, stereo, rng);
    SE3 estimate = perturbed(problem.truth);
    const PoseOptimizer optimizer(test::kitti_like_camera());
    const PoseOptimizationResult result =
        optimizer.optimize(estimate, problem.points, problem.observations);
    EXPECT_EQ(result.inliers, 200) << "stereo=" << stereo;
    EXPECT_LT((estimate.translation() - problem.truth.translation()).norm(), 1e-6);
    EXPECT_LT(test::rotation_error_deg(estimate, problem.truth), 1e-6);
  }
}

TEST(PoseOptimizer, FlagsGrossOutliersAndKeepsInliers) {
  std::mt19937 rng(2);
  PoseProblem problem = make_problem(300, true, rng);
  std::normal_distribution<double> pixel_noise(0.0, 0.5);
  std::vector<bool> is_outlier(problem.observations.size(), false);
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    PixelObservation& obs = problem.observations[i];
    if (i % 5 == 0) {
      obs.u += 40.0 + i % 7;  // 20% gross mismatches
      obs.v -= 25.0;
      obs.u_right += 40.0;
      is_outlier[i] = true;
    } else {
      obs.u += pixel_noise(rng);
      obs.v += pixel_noise(rng);
      obs.u_right += pixel_noise(rng);
    }
  }
  SE3 estimate = perturbed(problem.truth);
  const PoseOptimizer optimizer(test::kitti_like_camera());
  const PoseOptimizationResult result =
      optimizer.optimize(estimate, problem.points, problem.observations);

  int missed = 0, false_alarms = 0;
  for (std::size_t i = 0; i < is_outlier.size(); ++i) {
    if (is_outlier[i] && !result.outlier[i]) ++missed;
    if (!is_outlier[i] && result.outlier[i]) ++false_alarms;
  }
  EXPECT_EQ(missed, 0);
  EXPECT_LT(false_alarms, 12);  // 0.5 px noise: a few inliers fall past the 95% threshold
  EXPECT_LT((estimate.translation() - problem.truth.translation()).norm(), 0.02);
  EXPECT_LT(test::rotation_error_deg(estimate, problem.truth), 0.05);
}

// Two groups of observations disagree about the pose; doubling one group's weight must pull the
// solution towards it (the Salient BA mechanism).
TEST(PoseOptimizer, HigherWeightPullsTheSolutionTowardsItsObservations) {
  std::mt19937 rng(3);
  const RectifiedCamera cam = test::kitti_like_camera();
  const SE3 truth_a;                               // group A agrees with the identity pose
  const SE3 truth_b(SO3(), Vec3(0.05, 0.0, 0.0));  // group B with a pose shifted by 5 cm
  std::vector<Vec3> points = test::random_points(100, rng);
  std::vector<PixelObservation> obs;
  for (std::size_t i = 0; i < points.size(); ++i)
    obs.push_back(test::project(cam, i < 50 ? truth_a : truth_b, points[i], true));

  PoseOptimizerOptions options;
  options.rounds = 1;  // one robust solve; no reclassification, so both groups stay in
  const PoseOptimizer optimizer(cam, options);
  auto solve_x = [&](double weight_b) {
    for (std::size_t i = 50; i < obs.size(); ++i) obs[i].weight = weight_b;
    SE3 estimate;
    optimizer.optimize(estimate, points, obs);
    return estimate.translation().x();
  };
  const double x_equal = solve_x(1.0);
  const double x_double = solve_x(2.0);
  EXPECT_GT(x_equal, 0.005);
  EXPECT_LT(x_equal, 0.045);
  EXPECT_GT(x_double, x_equal + 0.003);  // moved towards group B's 0.05
}

TEST(PoseOptimizer, TooFewObservationsLeavePoseUnchanged) {
  std::mt19937 rng(4);
  const PoseProblem problem = make_problem(2, false, rng);
  SE3 estimate = perturbed(problem.truth);
  const SE3 before = estimate;
  const PoseOptimizer optimizer(test::kitti_like_camera());
  optimizer.optimize(estimate, problem.points, problem.observations);
  EXPECT_TRUE(estimate.matrix().isApprox(before.matrix()));
}

}  // namespace
}  // namespace sbaslam::optimize
