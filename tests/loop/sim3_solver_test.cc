#include "sbaslam/loop/sim3_solver.h"

#include <gtest/gtest.h>

#include "helper/expect_error.h"
#include "helper/sim3_scene.h"

namespace sbaslam::loop {
namespace {

Sim3 random_sim3(sim::Random& random, bool unit_scale) {
  const Vec3 phi(random.uniform(-2.0, 2.0), random.uniform(-2.0, 2.0), random.uniform(-2.0, 2.0));
  const Vec3 t(random.uniform(-5.0, 5.0), random.uniform(-5.0, 5.0), random.uniform(-5.0, 5.0));
  return Sim3(unit_scale ? 1.0 : std::exp(random.uniform(-1.5, 1.5)), SO3::exp(phi), t);
}

std::vector<Vec3> random_points(int count, sim::Random& random) {
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
    points.emplace_back(random.uniform(-3.0, 3.0), random.uniform(-3.0, 3.0),
                        random.uniform(1.0, 9.0));
  return points;
}

TEST(AlignPoints, RecoversRandomSimilarityAndRigidMotionExactly) {
  sim::Random random(7);
  for (int trial = 0; trial < 20; ++trial) {
    const bool fix_scale = trial % 2 == 1;
    const Sim3 truth = random_sim3(random, fix_scale);
    // The minimal case (3 pairs) and an overdetermined one.
    for (int count : {3, 25}) {
      const std::vector<Vec3> p2 = random_points(count, random);
      std::vector<Vec3> p1;
      for (const Vec3& p : p2) p1.push_back(truth * p);
      const Sim3 S12 = align_points(p1, p2, fix_scale);
      EXPECT_LT((S12.matrix() - truth.matrix()).norm(), 1e-9) << "trial " << trial;
      if (fix_scale) {
        EXPECT_EQ(S12.scale(), 1.0);
      }
    }
  }
}

TEST(AlignPoints, FixScaleIgnoresAScaleInTheData) {
  sim::Random random(8);
  const Sim3 truth(2.0, SO3::exp(Vec3(0.1, 0.2, -0.3)), Vec3(1.0, 2.0, 3.0));
  const std::vector<Vec3> p2 = random_points(30, random);
  std::vector<Vec3> p1;
  for (const Vec3& p : p2) p1.push_back(truth * p);
  const Sim3 S12 = align_points(p1, p2, true);
  EXPECT_EQ(S12.scale(), 1.0);
  // The rotation of a scaled copy is still found: the scale does not change the covariance's axes.
  EXPECT_LT(test::rotation_error_deg(S12, truth), 1e-9);
}

TEST(AlignPoints, RejectsTooFewMismatchedAndCollinearPoints) {
  const std::vector<Vec3> two = {Vec3(0, 0, 1), Vec3(1, 0, 2)};
  test::expect_error_naming([&] { align_points(two, two, false); }, "at least 3");
  const std::vector<Vec3> three = {Vec3(0, 0, 1), Vec3(1, 0, 2), Vec3(0, 1, 3)};
  test::expect_error_naming([&] { align_points(three, two, false); }, "3 points in keyframe 1");
  const std::vector<Vec3> line = {Vec3(0, 0, 1), Vec3(1, 1, 2), Vec3(2, 2, 3), Vec3(-1, -1, 0)};
  test::expect_error_naming([&] { align_points(line, line, false); }, "collinear");
  const std::vector<Vec3> same(4, Vec3(1, 2, 3));
  test::expect_error_naming(
      [&] {
        align_points(three, {same.begin(), same.begin() + 3}, true);
      },
      "coincident");
}

struct Classification {
  double precision = 0.0, recall = 0.0;
};

// Of the pairs flagged inlier, how many are right (precision); of the right ones, how many are
// flagged (recall).
Classification classify(const std::vector<char>& inliers, const std::vector<char>& is_wrong) {
  int flagged = 0, flagged_right = 0, right = 0;
  for (std::size_t i = 0; i < inliers.size(); ++i) {
    flagged += inliers[i];
    flagged_right += inliers[i] && !is_wrong[i];
    right += !is_wrong[i];
  }
  return {flagged_right / static_cast<double>(flagged), flagged_right / static_cast<double>(right)};
}

test::Sim3SceneSpec noisy_spec(double wrong_fraction, double scale, std::uint64_t seed) {
  test::Sim3SceneSpec spec;
  spec.count = 150;
  spec.wrong_fraction = wrong_fraction;
  spec.pixel_noise = 0.5;
  spec.depth_noise = 0.001;
  spec.scale = scale;
  spec.seed = seed;
  return spec;
}

TEST(RansacSim3, FindsTheSimilarityAndFlagsWrongMatches) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.4, 1.4, seed));
    Sim3RansacOptions options;
    options.seed = seed;
    const Sim3RansacResult result = ransac_sim3(scene.pairs, scene.camera1, scene.camera2, options);
    ASSERT_TRUE(result.found) << "seed " << seed;
    EXPECT_LT(test::rotation_error_deg(result.S12, scene.S12), 0.3);
    EXPECT_NEAR(result.S12.scale() / scene.S12.scale(), 1.0, 0.01);
    EXPECT_LT((result.S12.translation() - scene.S12.translation()).norm(), 0.1);
    const Classification c = classify(result.inliers, scene.is_wrong);
    EXPECT_GE(c.precision, 0.99) << "seed " << seed;
    EXPECT_GE(c.recall, 0.9) << "seed " << seed;
    int count = 0;
    for (char inlier : result.inliers) count += inlier;
    EXPECT_EQ(count, result.inlier_count);
    // The result is the refit on all inliers, not a 3-point hypothesis.
    std::vector<Vec3> p1, p2;
    for (std::size_t i = 0; i < scene.pairs.size(); ++i) {
      if (!result.inliers[i]) continue;
      p1.push_back(scene.pairs[i].p1_c);
      p2.push_back(scene.pairs[i].p2_c);
    }
    EXPECT_LT((align_points(p1, p2, false).matrix() - result.S12.matrix()).norm(), 1e-9);
    EXPECT_LE(result.iterations, options.max_iterations);
  }
}

TEST(RansacSim3, FixScaleFindsTheRigidMotionOfAStereoLoop) {
  const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.4, 1.0, 4));
  Sim3RansacOptions options;
  options.fix_scale = true;
  const Sim3RansacResult result = ransac_sim3(scene.pairs, scene.camera1, scene.camera2, options);
  ASSERT_TRUE(result.found);
  EXPECT_EQ(result.S12.scale(), 1.0);
  EXPECT_LT(test::rotation_error_deg(result.S12, scene.S12), 0.3);
  EXPECT_LT((result.S12.translation() - scene.S12.translation()).norm(), 0.1);
  EXPECT_GE(classify(result.inliers, scene.is_wrong).precision, 0.99);
}

// A wrong match whose KF2 point lies on KF1's ray of the keypoint: it reprojects onto uv1 in
// image 1, and only the test in image 2 rejects it.
TEST(RansacSim3, PairsThatFitOneImageOnlyAreOutliers) {
  test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.0, 1.4, 10));
  const Sim3 S21 = scene.S12.inverse();
  std::vector<char> on_ray(scene.pairs.size(), 0);
  for (std::size_t i = 0; i < scene.pairs.size(); i += 3) {
    Sim3Correspondence& pair = scene.pairs[i];
    pair.p2_c = S21 * (1.5 * pair.p1_c);
    pair.uv2 = scene.camera2.project(pair.p2_c);
    on_ray[i] = 1;
  }
  const Sim3RansacResult result =
      ransac_sim3(scene.pairs, scene.camera1, scene.camera2, Sim3RansacOptions{});
  ASSERT_TRUE(result.found);
  const Classification c = classify(result.inliers, on_ray);
  EXPECT_EQ(c.precision, 1.0);
  EXPECT_GE(c.recall, 0.9);
}

TEST(RansacSim3, SameSeedGivesTheSameResult) {
  const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.6, 1.4, 5));
  Sim3RansacOptions options;
  options.seed = 42;
  const Sim3RansacResult a = ransac_sim3(scene.pairs, scene.camera1, scene.camera2, options);
  const Sim3RansacResult b = ransac_sim3(scene.pairs, scene.camera1, scene.camera2, options);
  ASSERT_TRUE(a.found);
  EXPECT_EQ(a.S12.matrix(), b.S12.matrix());
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(RansacSim3, RandomCorrespondencesAreNotALoop) {
  for (std::uint64_t seed : {6, 7}) {
    const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(1.0, 1.4, seed));
    const Sim3RansacResult result =
        ransac_sim3(scene.pairs, scene.camera1, scene.camera2, Sim3RansacOptions{});
    EXPECT_FALSE(result.found) << "seed " << seed;
    EXPECT_LT(result.inlier_count, 20);
    EXPECT_EQ(result.iterations, Sim3RansacOptions{}.max_iterations);
  }
}

TEST(RansacSim3, TooFewCorrespondencesAreNotALoop) {
  const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.0, 1.4, 8));
  Sim3RansacOptions options;
  for (std::size_t count : {0, 2, 19}) {
    const std::vector<Sim3Correspondence> few(scene.pairs.begin(), scene.pairs.begin() + count);
    const Sim3RansacResult result = ransac_sim3(few, scene.camera1, scene.camera2, options);
    EXPECT_FALSE(result.found) << count;
    EXPECT_EQ(result.iterations, 0);
    EXPECT_EQ(result.inliers.size(), count);
  }
  // A small loop is still found when the caller lowers the bar.
  options.min_inliers = 3;
  const std::vector<Sim3Correspondence> three(scene.pairs.begin(), scene.pairs.begin() + 3);
  EXPECT_TRUE(ransac_sim3(three, scene.camera1, scene.camera2, options).found);
}

TEST(RansacSim3, RejectsInvalidOptions) {
  const test::Sim3Scene scene = test::make_sim3_scene(noisy_spec(0.0, 1.4, 9));
  const auto run = [&](Sim3RansacOptions options) {
    ransac_sim3(scene.pairs, scene.camera1, scene.camera2, options);
  };
  Sim3RansacOptions options;
  options.probability = 1.0;
  test::expect_error_naming([&] { run(options); }, "probability");
  options = {};
  options.min_inliers = 2;
  test::expect_error_naming([&] { run(options); }, "min_inliers");
  options = {};
  options.max_iterations = 0;
  test::expect_error_naming([&] { run(options); }, "max_iterations");
  options = {};
  options.chi2 = 0.0;
  test::expect_error_naming([&] { run(options); }, "chi2");
}

}  // namespace
}  // namespace sbaslam::loop
