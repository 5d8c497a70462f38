#include "sbaslam/optimize/sim3_refinement.h"

#include <gtest/gtest.h>

#include "helper/expect_error.h"
#include "helper/sim3_scene.h"

namespace sbaslam::optimize {
namespace {

test::Sim3Scene noisy_scene(double scale, std::uint64_t seed) {
  test::Sim3SceneSpec spec;
  spec.count = 120;
  spec.pixel_noise = 0.5;
  spec.depth_noise = 0.002;
  spec.scale = scale;
  spec.seed = seed;
  return test::make_sim3_scene(spec);
}

// A perturbation of the size a 3-point RANSAC hypothesis can be off by.
Sim3 perturbed(const Sim3& S, bool keep_scale) {
  Vec7 delta;
  delta << 0.15, -0.1, 0.2, 0.02, -0.015, 0.01, keep_scale ? 0.0 : 0.05;
  const Sim3 step = Sim3::exp(delta);
  return keep_scale ? Sim3(1.0, step.so3(), step.translation()) * S : step * S;
}

struct Errors {
  double rotation_deg, translation, log_scale;
};

Errors errors(const Sim3& estimate, const Sim3& truth) {
  return {test::rotation_error_deg(estimate, truth),
          (estimate.translation() - truth.translation()).norm(),
          std::abs(std::log(estimate.scale() / truth.scale()))};
}

TEST(RefineSim3, ConvergesFromAPerturbedInitialValue) {
  for (std::uint64_t seed : {1, 2}) {
    const test::Sim3Scene scene = noisy_scene(1.4, seed);
    const Sim3 initial = perturbed(scene.S12, false);
    const Sim3RefinementResult result =
        refine_sim3(scene.pairs, initial, scene.camera1, scene.camera2, Sim3RefinementOptions{});
    const Errors before = errors(initial, scene.S12), after = errors(result.S12, scene.S12);
    EXPECT_LT(after.rotation_deg, 0.1 * before.rotation_deg) << "seed " << seed;
    EXPECT_LT(after.translation, 0.1 * before.translation);
    EXPECT_LT(after.log_scale, 0.1 * before.log_scale);
    EXPECT_LT(after.rotation_deg, 0.1);
    EXPECT_LT(after.translation, 0.02);
    EXPECT_LT(after.log_scale, 0.005);
    EXPECT_GE(result.inlier_count, 115);
  }
}

TEST(RefineSim3, NoiseFreePairsGiveTheTruth) {
  test::Sim3SceneSpec spec;
  spec.count = 60;
  const test::Sim3Scene scene = test::make_sim3_scene(spec);
  Sim3RefinementOptions options;
  options.iterations_first = options.iterations_second = 20;
  const Sim3RefinementResult result =
      refine_sim3(scene.pairs, perturbed(scene.S12, false), scene.camera1, scene.camera2, options);
  EXPECT_LT((result.S12.matrix() - scene.S12.matrix()).norm(), 1e-6);
  EXPECT_EQ(result.inlier_count, 60);
}

TEST(RefineSim3, FixScaleReturnsUnitScale) {
  const test::Sim3Scene scene = noisy_scene(1.0, 3);
  const Sim3 initial = perturbed(scene.S12, true);
  ASSERT_EQ(initial.scale(), 1.0);
  Sim3RefinementOptions options;
  options.fix_scale = true;
  const Sim3RefinementResult result =
      refine_sim3(scene.pairs, initial, scene.camera1, scene.camera2, options);
  EXPECT_EQ(result.S12.scale(), 1.0);
  const Errors before = errors(initial, scene.S12), after = errors(result.S12, scene.S12);
  EXPECT_LT(after.rotation_deg, 0.1 * before.rotation_deg);
  EXPECT_LT(after.translation, 0.1 * before.translation);
  EXPECT_GE(result.inlier_count, 115);
}

// A unit scale cannot explain keyframe 2's scale drift: with the scale held, the refinement moves
// R and t away from the true ones to fit the images as well as a rigid motion can. Had the scale
// been free inside the optimisation, they would have stayed at the truth.
TEST(RefineSim3, FixScaleHoldsTheScaleInsideTheOptimisation) {
  const test::Sim3Scene scene = noisy_scene(1.4, 7);
  const Sim3 initial(1.0, scene.S12.so3(), scene.S12.translation());
  Sim3RefinementOptions options;
  options.fix_scale = true;
  options.huber_chi2 = 1e6;  // keep every pair: the test is about the fit, not the gate
  const Sim3RefinementResult result =
      refine_sim3(scene.pairs, initial, scene.camera1, scene.camera2, options);
  EXPECT_EQ(result.S12.scale(), 1.0);
  EXPECT_GT((result.S12.translation() - scene.S12.translation()).norm(), 0.1);
}

TEST(RefineSim3, FlagsMismatchedPairsAndPointsBehindACamera) {
  test::Sim3Scene scene = noisy_scene(1.4, 4);
  std::vector<char> bad(scene.pairs.size(), 0);
  for (std::size_t i = 0; i < scene.pairs.size(); i += 10) {
    scene.pairs[i].uv1 += Vec2(25.0, -18.0);  // a wrong keypoint in KF1
    bad[i] = 1;
  }
  // A KF2 point that S12 carries behind camera 1.
  scene.pairs[5].p2_c = scene.S12.inverse() * Vec3(0.5, 0.2, -3.0);
  bad[5] = 1;
  // A wrong KF2 point on KF1's ray of uv1: only its error in image 2 shows.
  scene.pairs[7].p2_c = scene.S12.inverse() * (1.5 * scene.pairs[7].p1_c);
  scene.pairs[7].uv2 = scene.camera2.project(scene.pairs[7].p2_c);
  bad[7] = 1;
  const Sim3RefinementResult result =
      refine_sim3(scene.pairs, perturbed(scene.S12, false), scene.camera1, scene.camera2, {});
  ASSERT_EQ(result.inliers.size(), scene.pairs.size());
  int good_kept = 0, good = 0;
  for (std::size_t i = 0; i < bad.size(); ++i) {
    if (bad[i]) {
      EXPECT_FALSE(result.inliers[i]) << "pair " << i;
    }
    good += !bad[i];
    good_kept += !bad[i] && result.inliers[i];
  }
  EXPECT_GE(good_kept, good - 3);
  EXPECT_EQ(result.inlier_count, good_kept);
  EXPECT_LT(errors(result.S12, scene.S12).rotation_deg, 0.1);
}

// Wrong keypoints all off the same way pull a Huber fit off the truth; the second round, without
// the pairs the first one dropped, is free of that pull.
TEST(RefineSim3, SecondRoundIsFreeOfTheDroppedPairs) {
  for (std::uint64_t seed : {8, 9, 10}) {
    test::Sim3Scene scene = noisy_scene(1.4, seed);
    for (std::size_t i = 0; i < scene.pairs.size(); i += 3) scene.pairs[i].uv1 += Vec2(15.0, 0.0);
    const Sim3RefinementResult result =
        refine_sim3(scene.pairs, scene.S12, scene.camera1, scene.camera2, {});
    // With them kept, the scale comes out 2-3 % low on these scenes.
    EXPECT_LT(errors(result.S12, scene.S12).log_scale, 0.01) << "seed " << seed;
    EXPECT_GE(result.inlier_count, 60);
  }
}

TEST(RefineSim3, NoPairsLeavesTheInitialValue) {
  const test::Sim3Scene scene = noisy_scene(1.4, 5);
  const Sim3RefinementResult result =
      refine_sim3({}, scene.S12, scene.camera1, scene.camera2, Sim3RefinementOptions{});
  EXPECT_EQ(result.inlier_count, 0);
  EXPECT_LT((result.S12.matrix() - scene.S12.matrix()).norm(), 1e-12);
}

TEST(RefineSim3, RejectsInvalidInput) {
  test::Sim3Scene scene = noisy_scene(1.4, 6);
  Sim3RefinementOptions options;
  options.huber_chi2 = 0.0;
  test::expect_error_naming(
      [&] { refine_sim3(scene.pairs, scene.S12, scene.camera1, scene.camera2, options); },
      "huber_chi2");
  options = {};
  options.iterations_second = -1;
  test::expect_error_naming(
      [&] { refine_sim3(scene.pairs, scene.S12, scene.camera1, scene.camera2, options); },
      "iteration");
  scene.pairs[3].sigma2_2 = 0.0;
  test::expect_error_naming(
      [&] { refine_sim3(scene.pairs, scene.S12, scene.camera1, scene.camera2, {}); },
      "correspondence 3");
}

}  // namespace
}  // namespace sbaslam::optimize
