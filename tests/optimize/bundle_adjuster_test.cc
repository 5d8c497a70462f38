#include "sbaslam/optimize/bundle_adjuster.h"

#include <gtest/gtest.h>

#include "helper/synthetic_views.h"

namespace sbaslam::optimize {
namespace {

struct Scene {
  std::vector<SE3> poses;
  std::vector<Vec3> points;
};

// Every camera sees every point; the first two keyframes are fixed (gauge and, for monocular,
// scale), the others and all points start perturbed.
BundleAdjustmentProblem make_problem(const Scene& scene, bool stereo, std::mt19937& rng) {
  BundleAdjustmentProblem problem;
  problem.camera = test::kitti_like_camera();
  std::normal_distribution<double> n(0.0, 1.0);
  for (std::size_t k = 0; k < scene.poses.size(); ++k) {
    BaKeyframe kf;
    kf.fixed = k < 2;
    Vec6 delta;
    delta << 0.05 * n(rng), 0.05 * n(rng), 0.05 * n(rng), 0.005 * n(rng), 0.005 * n(rng),
        0.005 * n(rng);
    kf.T_cw = kf.fixed ? scene.poses[k] : SE3::exp(delta) * scene.poses[k];
    problem.keyframes.push_back(kf);
  }
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    problem.points.push_back({scene.points[i] + 0.1 * Vec3(n(rng), n(rng), n(rng)), false});
    for (std::size_t k = 0; k < scene.poses.size(); ++k) {
      BaObservation o;
      o.keyframe = static_cast<int>(k);
      o.point = static_cast<int>(i);
      o.pixel = test::project(problem.camera, scene.poses[k], scene.points[i], stereo);
      problem.observations.push_back(o);
    }
  }
  return problem;
}

Scene make_scene(std::mt19937& rng) {
  return {test::camera_row(5, 1.0), test::random_points(150, rng)};
}

TEST(BundleAdjuster, NoiseFreeConvergesToTruth) {
  for (bool stereo : {false, true}) {
    std::mt19937 rng(7);
    const Scene scene = make_scene(rng);
    BundleAdjustmentProblem problem = make_problem(scene, stereo, rng);
    BundleAdjusterOptions options;
    options.iterations = 30;
    const BundleAdjustmentReport report = bundle_adjust(problem, options);
    ASSERT_TRUE(report.solved);
    EXPECT_EQ(report.outliers, 0) << "stereo=" << stereo;
    for (std::size_t k = 0; k < scene.poses.size(); ++k) {
      EXPECT_LT((problem.keyframes[k].T_cw.translation() - scene.poses[k].translation()).norm(),
                1e-5)
          << "keyframe " << k << " stereo=" << stereo;
      EXPECT_LT(test::rotation_error_deg(problem.keyframes[k].T_cw, scene.poses[k]), 1e-5);
    }
    for (std::size_t i = 0; i < scene.points.size(); ++i)
      EXPECT_LT((problem.points[i].position - scene.points[i]).norm(), 1e-4);
  }
}

TEST(BundleAdjuster, FlagsCorruptedObservationsAndKeepsFixedKeyframes) {
  std::mt19937 rng(8);
  const Scene scene = make_scene(rng);
  BundleAdjustmentProblem problem = make_problem(scene, true, rng);
  std::vector<bool> corrupted(problem.observations.size(), false);
  for (std::size_t i = 0; i < problem.observations.size(); i += 17) {
    problem.observations[i].pixel.u += 30.0;
    problem.observations[i].pixel.u_right += 30.0;
    corrupted[i] = true;
  }
  const SE3 fixed_before = problem.keyframes[0].T_cw;
  BundleAdjusterOptions options;
  options.iterations = 20;
  const BundleAdjustmentReport report = bundle_adjust(problem, options);

  int missed = 0, false_alarms = 0;
  for (std::size_t i = 0; i < corrupted.size(); ++i) {
    if (corrupted[i] && !report.outlier[i]) ++missed;
    if (!corrupted[i] && report.outlier[i]) ++false_alarms;
  }
  EXPECT_EQ(missed, 0);
  EXPECT_EQ(false_alarms, 0);
  EXPECT_TRUE(problem.keyframes[0].T_cw.matrix().isApprox(fixed_before.matrix(), 0.0));
  for (std::size_t k = 2; k < scene.poses.size(); ++k)
    EXPECT_LT((problem.keyframes[k].T_cw.translation() - scene.poses[k].translation()).norm(),
              1e-3);
}

TEST(BundleAdjuster, EmptyProblemIsNotSolved) {
  BundleAdjustmentProblem problem;
  EXPECT_FALSE(bundle_adjust(problem).solved);
}

}  // namespace
}  // namespace sbaslam::optimize
