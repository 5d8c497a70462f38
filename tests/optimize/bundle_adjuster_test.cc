#include "sbaslam/optimize/bundle_adjuster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

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

// Every 17th observation moved by 30 px.
BundleAdjustmentProblem corrupted_problem(Scene& scene, std::vector<bool>& corrupted) {
  std::mt19937 rng(8);
  scene = make_scene(rng);
  BundleAdjustmentProblem problem = make_problem(scene, true, rng);
  corrupted.assign(problem.observations.size(), false);
  for (std::size_t i = 0; i < problem.observations.size(); i += 17) {
    problem.observations[i].pixel.u += 30.0;
    problem.observations[i].pixel.u_right += 30.0;
    corrupted[i] = true;
  }
  return problem;
}

// The default scheme (ORB-SLAM2's: a robust pass, outliers dropped, a refinement) recovers
// the poses to 1 mm and flags exactly the corrupted observations.
TEST(BundleAdjuster, FlagsCorruptedObservationsAndKeepsFixedKeyframes) {
  Scene scene;
  std::vector<bool> corrupted;
  BundleAdjustmentProblem problem = corrupted_problem(scene, corrupted);
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

// One robust pass (ORB-SLAM3's local BA; our two-view initialiser) flags every corrupted
// observation too. Its Huber solution still feels the outliers (each pulls with a bounded force),
// so some good observations of the same points are flagged with them and the poses are less exact.
TEST(BundleAdjuster, OneRobustPassFlagsEveryCorruptedObservation) {
  Scene scene;
  std::vector<bool> corrupted;
  BundleAdjustmentProblem problem = corrupted_problem(scene, corrupted);
  BundleAdjusterOptions options;
  options.iterations = 10;
  options.refine_iterations = 0;
  const BundleAdjustmentReport report = bundle_adjust(problem, options);
  int missed = 0, flagged = 0;
  for (std::size_t i = 0; i < corrupted.size(); ++i) {
    if (corrupted[i] && !report.outlier[i]) ++missed;
    if (report.outlier[i]) ++flagged;
  }
  EXPECT_EQ(missed, 0);
  EXPECT_LT(flagged, 2 * static_cast<int>(std::count(corrupted.begin(), corrupted.end(), true)));
  for (std::size_t k = 2; k < scene.poses.size(); ++k)
    EXPECT_LT((problem.keyframes[k].T_cw.translation() - scene.poses[k].translation()).norm(),
              0.05);
}

// Local BA with stereo ends a pass once an iteration changes the cost by less than the function
// tolerance (here the robust pass alone). With outliers under the Huber kernel the pass converges
// slowly (each iteration reweights them), so the loose tolerance stops well before the tight one.
TEST(BundleAdjuster, FunctionToleranceEndsAPassEarly) {
  Scene scene;
  std::vector<bool> corrupted;
  const BundleAdjustmentProblem start = corrupted_problem(scene, corrupted);
  BundleAdjusterOptions tight;
  tight.iterations = 30;
  tight.refine_iterations = 0;
  tight.function_tolerance = 1e-12;
  BundleAdjusterOptions loose = tight;
  loose.function_tolerance = 1e-3;
  BundleAdjustmentProblem a = start, b = start;
  const BundleAdjustmentReport tight_report = bundle_adjust(a, tight);
  const BundleAdjustmentReport loose_report = bundle_adjust(b, loose);
  EXPECT_GE(loose_report.iterations, 1);
  EXPECT_LT(loose_report.iterations, tight_report.iterations);
  EXPECT_GE(loose_report.final_cost, tight_report.final_cost);
  EXPECT_LT(loose_report.final_cost, 1.01 * tight_report.final_cost);
}

// The refinement pass reuses the first pass's Ceres problem, removing the flagged observations and
// keeping the kernels (or, with refine_with_kernel false, switching them off). It must equal a
// robust (or plain) solve, started from the first pass's result, of the problem without those
// observations. Pixel noise and weights of 4 on every third observation put inliers beyond the
// Huber corner, where the kernel acts.
void expect_refinement_is_the_solve_without_the_flagged_observations(bool with_kernel) {
  Scene scene;
  std::vector<bool> corrupted;
  BundleAdjustmentProblem start = corrupted_problem(scene, corrupted);
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (std::size_t i = 0; i < start.observations.size(); ++i) {
    PixelObservation& pixel = start.observations[i].pixel;
    pixel.u += noise(rng);
    pixel.v += noise(rng);
    pixel.u_right += noise(rng);
    if (i % 3 == 0) pixel.weight = 4.0;
  }
  BundleAdjusterOptions options;
  options.iterations = 20;
  options.refine_with_kernel = with_kernel;
  BundleAdjustmentProblem two_passes = start;
  bundle_adjust(two_passes, options);

  BundleAdjusterOptions first_only = options;
  first_only.refine_iterations = 0;
  BundleAdjustmentProblem by_hand = start;
  const BundleAdjustmentReport first = bundle_adjust(by_hand, first_only);
  ASSERT_GT(first.outliers, 0);
  std::vector<BaObservation> kept;
  for (std::size_t i = 0; i < by_hand.observations.size(); ++i)
    if (!first.outlier[i]) kept.push_back(by_hand.observations[i]);
  by_hand.observations = kept;
  BundleAdjusterOptions plain = first_only;
  plain.iterations = options.refine_iterations;
  // Without the kernel: a corner no residual reaches, i.e. least squares.
  if (!with_kernel) plain.huber_mono = plain.huber_stereo = 1e9;
  bundle_adjust(by_hand, plain);

  double largest_step = 0.0;
  for (std::size_t k = 0; k < start.keyframes.size(); ++k) {
    const Vec3 t = two_passes.keyframes[k].T_cw.translation();
    EXPECT_LT((t - by_hand.keyframes[k].T_cw.translation()).norm(), 1e-9) << "keyframe " << k;
    largest_step = std::max(largest_step, (t - start.keyframes[k].T_cw.translation()).norm());
  }
  for (std::size_t i = 0; i < start.points.size(); ++i)
    EXPECT_LT((two_passes.points[i].position - by_hand.points[i].position).norm(), 1e-8);
  EXPECT_GT(largest_step, 1e-3);  // the passes moved the poses: the comparison is not trivial
}

TEST(BundleAdjuster, RefinementPassIsTheRobustSolveWithoutTheFlaggedObservations) {
  expect_refinement_is_the_solve_without_the_flagged_observations(true);
}

TEST(BundleAdjuster, PlainRefinementPassIsTheLeastSquaresSolveWithoutTheFlaggedObservations) {
  expect_refinement_is_the_solve_without_the_flagged_observations(false);
}

// Why the refinement keeps the kernel: a few strongly weighted observations (Salient BA's 257) that
// share a bias of 1.5 px, small enough to pass the chi-square test, as a blurred poster's corners
// do. Without the kernel they pull 257 times as hard as the rest and drag the keyframe; with it
// their pull is bounded, as in the robust pass.
TEST(BundleAdjuster, KernelInTheRefinementBoundsTheStrongWeightsOfABiasedCluster) {
  std::mt19937 rng(11);
  const Scene scene = make_scene(rng);
  BundleAdjustmentProblem start = make_problem(scene, true, rng);
  std::normal_distribution<double> noise(0.0, 0.5);
  const int biased_keyframe = 3;
  for (BaObservation& o : start.observations) {
    o.pixel.u += noise(rng);
    o.pixel.v += noise(rng);
    o.pixel.u_right += noise(rng);
    if (o.keyframe == biased_keyframe && o.point % 10 == 0) {
      o.pixel.u += 1.5;
      o.pixel.u_right += 1.5;
      o.pixel.weight = 257.0;
    }
  }
  const auto keyframe_error = [&](bool with_kernel) {
    BundleAdjustmentProblem problem = start;
    BundleAdjusterOptions options;
    options.iterations = 20;
    options.refine_with_kernel = with_kernel;
    const BundleAdjustmentReport report = bundle_adjust(problem, options);
    int biased_flagged = 0;
    for (std::size_t i = 0; i < problem.observations.size(); ++i)
      if (report.outlier[i] && problem.observations[i].pixel.weight > 1.0) ++biased_flagged;
    EXPECT_EQ(biased_flagged, 0) << "the biased observations must stay inliers";
    const SE3& T = problem.keyframes[biased_keyframe].T_cw;
    return (T.translation() - scene.poses[biased_keyframe].translation()).norm();
  };
  const double with_kernel = keyframe_error(true);
  const double without_kernel = keyframe_error(false);
  EXPECT_LT(with_kernel, 0.7 * without_kernel)
      << "with kernel " << with_kernel << " m, without " << without_kernel << " m";
}

// Local BA's weight_scale c: the same solve as the weights unscaled with the Huber corner at
// 1 / sqrt(c) of ORB-SLAM's (rho(c s) = c rho'(s)), and the same outlier flags (unweighted).
TEST(BundleAdjuster, WeightScaleMovesTheKernelCornerAndKeepsTheOutlierTest) {
  std::mt19937 rng(5);
  const Scene scene = make_scene(rng);
  BundleAdjustmentProblem start = make_problem(scene, true, rng);
  std::normal_distribution<double> noise(0.0, 0.7);
  std::uniform_real_distribution<double> saliency(0.0, 1.0);
  for (BaObservation& o : start.observations) {
    o.pixel.u += noise(rng);
    o.pixel.v += noise(rng);
    o.pixel.u_right += noise(rng);
    const double s = saliency(rng);
    o.pixel.weight = 256.0 * s * s + 1.0;
  }
  const double scale = 16.0 / 257.0;
  const auto solve = [&](double weight_scale, double corner_factor) {
    BundleAdjustmentProblem problem = start;
    BundleAdjusterOptions options;
    options.iterations = 20;
    options.weight_scale = weight_scale;
    options.huber_mono *= corner_factor;
    options.huber_stereo *= corner_factor;
    const BundleAdjustmentReport report = bundle_adjust(problem, options);
    return std::make_pair(problem, report.outlier);
  };
  const auto [scaled, scaled_outliers] = solve(scale, 1.0);
  const auto [wide, wide_outliers] = solve(1.0, 1.0 / std::sqrt(scale));
  const auto [unscaled, unscaled_outliers] = solve(1.0, 1.0);
  double same = 0.0, moved = 0.0;
  for (std::size_t k = 2; k < scene.poses.size(); ++k) {
    same = std::max(
        same,
        (scaled.keyframes[k].T_cw.translation() - wide.keyframes[k].T_cw.translation()).norm());
    moved = std::max(
        moved,
        (scaled.keyframes[k].T_cw.translation() - unscaled.keyframes[k].T_cw.translation()).norm());
  }
  EXPECT_LT(same, 1e-8);
  EXPECT_GT(moved, 1e-5) << "the scale must change the solve, else the test shows nothing";
  EXPECT_EQ(scaled_outliers, wide_outliers);
}

TEST(BundleAdjuster, EmptyProblemIsNotSolved) {
  BundleAdjustmentProblem problem;
  EXPECT_FALSE(bundle_adjust(problem).solved);
}

}  // namespace
}  // namespace sbaslam::optimize
