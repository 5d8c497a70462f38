#include "sbaslam/geometry/epipolar_models.h"

#include <gtest/gtest.h>

#include <numeric>

#include "geometry/two_view_scene.h"
#include "sbaslam/geometry/two_view_ransac.h"

namespace sbaslam::geometry {
namespace {

std::vector<int> all_indices(int n) {
  std::vector<int> indices(n);
  std::iota(indices.begin(), indices.end(), 0);
  return indices;
}

test::SceneSpec exact(bool planar) {
  test::SceneSpec spec;
  spec.planar = planar;
  spec.noise_px = 0.0;
  spec.outlier_fraction = 0.0;
  spec.points = 60;
  return spec;
}

TEST(NormalizePoints, ZeroMeanUnitMeanAbsoluteDeviation) {
  const NormalizedPoints n = normalize_points({{10, 20}, {30, 60}, {50, 20}, {30, 100}});
  Vec2 mean = Vec2::Zero(), dev = Vec2::Zero();
  for (const Vec2& p : n.points) mean += p;
  for (const Vec2& p : n.points) dev += p.cwiseAbs();
  EXPECT_NEAR(mean.norm(), 0.0, 1e-12);
  EXPECT_NEAR(dev.x() / 4.0, 1.0, 1e-12);
  EXPECT_NEAR(dev.y() / 4.0, 1.0, 1e-12);
  EXPECT_NEAR((n.T * Vec3(50, 20, 1)).hnormalized().x(), n.points[2].x(), 1e-12);
}

TEST(HomographyDlt, ExactPlaneGivesZeroTransferError) {
  const auto s = test::make_scene(exact(true));
  const Correspondences c = test::correspondences_of(s);
  const NormalizedPoints n1 = normalize_points(c.p1), n2 = normalize_points(c.p2);
  const Mat3 H =
      n2.T.inverse() * homography_dlt(n1.points, n2.points, {0, 5, 10, 15, 20, 25}) * n1.T;
  for (int i = 0; i < c.size(); ++i)
    EXPECT_NEAR(((H * c.p1[i].homogeneous()).hnormalized() - c.p2[i]).norm(), 0.0, 1e-3);
  const ModelScore score = score_homography(H, c);
  EXPECT_EQ(score.inlier_count, c.size());
  EXPECT_NEAR(score.score, 2 * kChi2TwoDof * c.size(), 1e-3);
}

TEST(HomographyDlt, NonPlanarSceneIsNotAHomography) {
  const auto s = test::make_scene(exact(false));
  const Correspondences c = test::correspondences_of(s);
  const NormalizedPoints n1 = normalize_points(c.p1), n2 = normalize_points(c.p2);
  const Mat3 H =
      n2.T.inverse() * homography_dlt(n1.points, n2.points, all_indices(c.size())) * n1.T;
  EXPECT_LT(score_homography(H, c).inlier_count, c.size() / 2);
}

TEST(Fundamental8Point, ExactSceneSatisfiesTheEpipolarConstraint) {
  const auto s = test::make_scene(exact(false));
  const Correspondences c = test::correspondences_of(s);
  const NormalizedPoints n1 = normalize_points(c.p1), n2 = normalize_points(c.p2);
  const Mat3 F = n2.T.transpose() *
                 fundamental_8point(n1.points, n2.points, {0, 7, 14, 21, 28, 35, 42, 49}) * n1.T;
  EXPECT_NEAR(F.determinant() / F.norm(), 0.0, 1e-9);
  for (int i = 0; i < c.size(); ++i) EXPECT_NEAR(epipolar_distance2(F, c.p1[i], c.p2[i]), 0, 1e-4);
  EXPECT_EQ(score_fundamental(F, c).inlier_count, c.size());
}

TEST(ScoreFundamental, GatesEachDirectionAtOneDofAndScoresAtTwoDof) {
  // F of a pure x-translation: epipolar lines are image rows, distance = vertical offset.
  Mat3 F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  Correspondences c;
  c.add({100, 50}, {140, 50});               // on the line: scores 2 * 5.991
  c.add({100, 50}, {140, 51.5});             // 1.5 px: chi2 2.25 in both images -> inlier
  c.add({100, 50}, {140, 52.0}, 1.0, 0.25);  // 2 px but sigma^2 = 4 in image 2: chi2 1 and 4
  const ModelScore s = score_fundamental(F, c);
  EXPECT_EQ(s.inliers, (std::vector<char>{1, 1, 0}));
  // The third match fails in image 1 (chi2 4 > 3.841) but its image-2 direction still scores.
  EXPECT_NEAR(s.score, 2 * kChi2TwoDof + 2 * (kChi2TwoDof - 2.25) + (kChi2TwoDof - 1.0), 1e-9);
}

TEST(SampleMinimalSets, DistinctIndicesAndSeeded) {
  const auto a = sample_minimal_sets(20, 50, 7), b = sample_minimal_sets(20, 50, 7);
  const auto other = sample_minimal_sets(20, 50, 8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, other);
  for (const MinimalSet& set : a) {
    std::vector<int> sorted(set.begin(), set.end());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
    EXPECT_GE(sorted.front(), 0);
    EXPECT_LT(sorted.back(), 20);
  }
}

TEST(Ransac, FindsTheModelDespiteOutliers) {
  test::SceneSpec spec;
  spec.outlier_fraction = 0.3;
  const auto s = test::make_scene(spec);
  const Correspondences c = test::correspondences_of(s);
  const ModelFit fit = ransac_fundamental(c, sample_minimal_sets(c.size(), 200, 3));
  int outliers = 0, accepted_outliers = 0, inliers = 0, kept_inliers = 0;
  for (int i = 0; i < c.size(); ++i) {
    outliers += s.outlier[i];
    accepted_outliers += s.outlier[i] && fit.score.inliers[i];
    inliers += !s.outlier[i];
    kept_inliers += !s.outlier[i] && fit.score.inliers[i];
  }
  ASSERT_GT(outliers, 60);
  // An outlier can fall near its epipolar line by chance (about 1 in 100); a handful at most.
  EXPECT_LE(accepted_outliers, 4);
  // The 95% gates in both images reject about a tenth of the true matches.
  EXPECT_GT(kept_inliers, 0.8 * inliers);
}

}  // namespace
}  // namespace sbaslam::geometry
