#include "sbaslam/loop/loop_detector.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "helper/circular_map.h"
#include "helper/synthetic_views.h"

namespace sbaslam::loop {
namespace {

// Feeds the keyframes in order, as local mapping hands them over; returns the first loop.
std::optional<DetectedLoop> first_loop(const test::CircularMap& c, const Vocabulary& vocabulary,
                                       LoopDetector& detector, std::size_t keyframes) {
  for (std::size_t i = 0; i < keyframes; ++i) {
    BowVector bow;
    FeatureVector features;
    vocabulary.transform(c.keyframes[i]->measurements().descriptors, bow, features, 2);
    auto loop = detector.process(c.keyframes[i], std::move(bow), std::move(features));
    if (loop) return loop;
  }
  return std::nullopt;
}

// Median reprojection error, in pixels, of the loop's matched points under S_cw.
double median_reprojection_error(const DetectedLoop& loop) {
  std::vector<double> errors;
  for (std::size_t k = 0; k < loop.matched.size(); ++k) {
    if (!loop.matched[k]) continue;
    const Vec2 uv = loop.current->rig().camera.project(loop.S_cw * loop.matched[k]->position());
    const feature::OrbKeypoint& kp = loop.current->measurements().keypoints_un[k];
    errors.push_back((uv - Vec2(kp.x, kp.y)).norm());
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

TEST(LoopDetector, LinksTheSecondLapToTheFirstWhereTheySeeTheSameWall) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopDetector detector(c->rig, LoopDetectorOptions{});
  const auto loop = first_loop(*c, vocabulary, detector, c->keyframes.size());
  ASSERT_TRUE(loop.has_value());
  // The second lap's keyframes (from 30 on, 300 degrees) see the wall the first lap's first
  // keyframes saw; three consecutive ones must agree on the place first.
  EXPECT_GE(loop->current->id(), 30u);
  EXPECT_LE(loop->loop->id(), 8u);
  EXPECT_GE(loop->loop_matches, 40);
  EXPECT_GE(loop->sim3_inliers, 20);
  EXPECT_LT(median_reprojection_error(*loop), 2.0);
  // Seen over a narrow view of a far wall at one depth, scale and distance trade against each
  // other, so the similarity is judged by how well it lays the loop's points over the keypoints.
  EXPECT_NEAR(loop->S_cw.scale(), 1.0, 0.1);
}

// A similarity that explains too few of the BoW matches marks an ambiguous place: no loop.
TEST(LoopDetector, RequiresTheSimilarityToExplainItsShareOfTheMatches) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopDetectorOptions options;
  options.min_inlier_ratio = 1.01;  // more than every match
  LoopDetector detector(c->rig, options);
  EXPECT_FALSE(first_loop(*c, vocabulary, detector, c->keyframes.size()).has_value());
}

TEST(LoopDetector, FindsNoLoopOnTheFirstLap) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopDetector detector(c->rig, LoopDetectorOptions{});
  EXPECT_FALSE(first_loop(*c, vocabulary, detector, 28).has_value());
  EXPECT_EQ(detector.keyframes_filed(), 28u);
}

TEST(LoopDetector, SameInputAndSeedGiveTheSameLoop) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopDetector a(c->rig, LoopDetectorOptions{}), b(c->rig, LoopDetectorOptions{});
  const auto la = first_loop(*c, vocabulary, a, c->keyframes.size());
  const auto lb = first_loop(*c, vocabulary, b, c->keyframes.size());
  ASSERT_TRUE(la && lb);
  EXPECT_EQ(la->loop, lb->loop);
  EXPECT_EQ(la->S_cw.matrix(), lb->S_cw.matrix());
  EXPECT_EQ(la->matched, lb->matched);
}

TEST(LoopDetector, ProjectionSearchAddsTheLoopsPointsUnderTheSimilarity) {
  auto c = test::make_circular_map();
  map::KeyFrame* current = c->keyframes[39];
  std::vector<map::MapPoint*> points;
  for (map::MapPoint* mp : c->keyframes[3]->map_points())
    if (mp) points.push_back(mp);
  std::vector<map::MapPoint*> matched(current->keypoint_count(), nullptr);
  const int added =
      match_points_by_similarity(*current, Sim3(c->ideal_T_cw(39, 3)), points, matched, 10.0f);
  EXPECT_GT(added, static_cast<int>(points.size()) * 2 / 5);
  int right = 0;
  for (std::size_t k = 0; k < matched.size(); ++k)
    if (matched[k] && matched[k] == c->first_point[c->world_point_of[39][k]]) ++right;
  EXPECT_GE(right, added * 95 / 100);
  // Under a pose 20 degrees off, the same points land elsewhere and hardly match.
  std::vector<map::MapPoint*> off(current->keypoint_count(), nullptr);
  const SE3 wrong = SE3(SO3::exp(Vec3(0.0, 0.35, 0.0)), Vec3::Zero()) * c->ideal_T_cw(39, 3);
  EXPECT_LT(match_points_by_similarity(*current, Sim3(wrong), points, off, 10.0f), added / 10);
}

}  // namespace
}  // namespace sbaslam::loop
