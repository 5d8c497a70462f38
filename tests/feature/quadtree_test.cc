#include "sbaslam/feature/quadtree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace sbaslam::feature {
namespace {

std::vector<cv::KeyPoint> random_candidates(int n, float width, float height, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(0.0f, width), y(0.0f, height), r(1.0f, 100.0f);
  std::vector<cv::KeyPoint> out;
  for (int i = 0; i < n; ++i) out.emplace_back(cv::Point2f(x(rng), y(rng)), 7.0f, -1.0f, r(rng));
  return out;
}

TEST(Quadtree, KeepsAboutTheWantedNumber) {
  const auto candidates = random_candidates(5000, 1200.0f, 340.0f, 1);
  QuadtreeDistributor quadtree;
  std::vector<int> kept;
  for (int wanted : {1, 10, 100, 434, 1000}) {
    quadtree.distribute(candidates, cv::Rect2f(0, 0, 1200, 340), wanted, kept);
    EXPECT_GE(static_cast<int>(kept.size()), wanted);
    EXPECT_LE(static_cast<int>(kept.size()), wanted + 3);
    EXPECT_EQ(std::set<int>(kept.begin(), kept.end()).size(), kept.size()) << "duplicates";
  }
}

TEST(Quadtree, FewerCandidatesThanWantedKeepsThemAll) {
  const auto candidates = random_candidates(50, 300.0f, 200.0f, 2);
  QuadtreeDistributor quadtree;
  std::vector<int> kept;
  quadtree.distribute(candidates, cv::Rect2f(0, 0, 300, 200), 100, kept);
  EXPECT_EQ(kept.size(), 50u);
  quadtree.distribute({}, cv::Rect2f(0, 0, 300, 200), 100, kept);
  EXPECT_TRUE(kept.empty());
}

TEST(Quadtree, SpreadsInsteadOfTakingTheStrongest) {
  // 1000 strong candidates piled in one corner, 100 weak ones spread out: the quadtree keeps
  // only a few from the pile.
  std::vector<cv::KeyPoint> candidates = random_candidates(1000, 40.0f, 40.0f, 3);
  for (auto& c : candidates) c.response += 1000.0f;
  const auto spread = random_candidates(100, 400.0f, 400.0f, 4);
  candidates.insert(candidates.end(), spread.begin(), spread.end());
  QuadtreeDistributor quadtree;
  std::vector<int> kept;
  quadtree.distribute(candidates, cv::Rect2f(0, 0, 400, 400), 64, kept);
  const auto from_pile = std::count_if(kept.begin(), kept.end(), [](int i) { return i < 1000; });
  EXPECT_LT(from_pile, 16);
}

TEST(Quadtree, EachNodeKeepsItsStrongest) {
  // Two candidates close together, far from a third: with 2 wanted the pair shares a node and
  // the stronger one is kept.
  std::vector<cv::KeyPoint> candidates = {cv::KeyPoint(cv::Point2f(10, 10), 7, -1, 5.0f),
                                          cv::KeyPoint(cv::Point2f(11, 11), 7, -1, 9.0f),
                                          cv::KeyPoint(cv::Point2f(90, 90), 7, -1, 1.0f)};
  QuadtreeDistributor quadtree;
  std::vector<int> kept;
  quadtree.distribute(candidates, cv::Rect2f(0, 0, 100, 100), 2, kept);
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, (std::vector<int>{1, 2}));
}

}  // namespace
}  // namespace sbaslam::feature
