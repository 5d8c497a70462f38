#include "sbaslam/match/feature_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "sbaslam/core/error.h"

namespace sbaslam::match {
namespace {

std::vector<feature::OrbKeypoint> random_keypoints(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(-20.0f, 780.0f), y(-20.0f, 500.0f);
  std::uniform_int_distribution<int> octave(0, 7);
  std::vector<feature::OrbKeypoint> kps(n);
  for (auto& kp : kps) {
    kp.x = x(rng);
    kp.y = y(rng);
    kp.octave = octave(rng);
  }
  return kps;
}

TEST(FeatureGrid, AreaQueriesMatchBruteForce) {
  const auto kps = random_keypoints(3000, 11);
  const cv::Rect2f bounds(-25.0f, -25.0f, 810.0f, 530.0f);
  const FeatureGrid grid(kps, bounds);
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> x(-50.0f, 800.0f), y(-50.0f, 520.0f), r(0.5f, 60.0f);
  std::uniform_int_distribution<int> level(-1, 7);
  for (int q = 0; q < 500; ++q) {
    const float qx = x(rng), qy = y(rng), qr = r(rng);
    const int min_level = std::max(0, level(rng)), max_level = level(rng);
    std::vector<int> expected;
    for (int i = 0; i < static_cast<int>(kps.size()); ++i) {
      if (kps[i].octave < min_level || (max_level >= 0 && kps[i].octave > max_level)) continue;
      if (std::abs(kps[i].x - qx) < qr && std::abs(kps[i].y - qy) < qr) expected.push_back(i);
    }
    std::vector<int> got = grid.features_in_area(qx, qy, qr, min_level, max_level);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << "query " << q;
  }
}

TEST(FeatureGrid, PointsOutsideTheBoundsAreNotIndexed) {
  std::vector<feature::OrbKeypoint> kps(2);
  kps[0].x = 10.0f;
  kps[0].y = 10.0f;
  kps[1].x = -5.0f;  // outside
  kps[1].y = 10.0f;
  const FeatureGrid grid(kps, cv::Rect2f(0, 0, 100, 100), 10, 10);
  EXPECT_EQ(grid.features_in_area(5.0f, 10.0f, 20.0f), std::vector<int>{0});
  EXPECT_TRUE(grid.features_in_area(5.0f, 10.0f, 0.0f).empty());
  EXPECT_THROW(FeatureGrid(kps, cv::Rect2f(0, 0, 0, 100)), Error);
}

}  // namespace
}  // namespace sbaslam::match
