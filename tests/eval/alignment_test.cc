#include "sbaslam/eval/alignment.h"

#include <gtest/gtest.h>

#include <random>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

// Random poses spread over a few metres (seeded: the test is deterministic).
PoseSeries random_poses(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-5.0, 5.0);
  std::uniform_real_distribution<double> angle(-1.0, 1.0);
  PoseSeries series;
  for (std::size_t i = 0; i < n; ++i) {
    const SE3 pose(SO3::exp(Vec3(angle(rng), angle(rng), angle(rng))),
                   Vec3(position(rng), position(rng), position(rng)));
    series.stamps.push_back(static_cast<double>(i));
    series.poses.push_back(pose.matrix());
  }
  return series;
}

// reference = S * estimate, for a similarity S = (scale, R, t) acting on poses like evo's sim3.
PoseSeries apply_similarity(const PoseSeries& estimate, double scale, const Mat3& R,
                            const Vec3& t) {
  PoseSeries out = estimate;
  for (Mat4& pose : out.poses) {
    pose.topLeftCorner<3, 3>() = R * pose.topLeftCorner<3, 3>();
    pose.topRightCorner<3, 1>() = scale * (R * pose.topRightCorner<3, 1>()) + t;
  }
  return out;
}

void expect_poses_near(const PoseSeries& a, const PoseSeries& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_LE((a.poses[i] - b.poses[i]).cwiseAbs().maxCoeff(), tol) << "pose " << i;
}

const Mat3 kRotation = SO3::exp(Vec3(0.3, -1.2, 2.0)).matrix();
const Vec3 kTranslation(4.0, -2.5, 0.7);

TEST(Umeyama, RecoversAKnownSim3Exactly) {
  const PoseSeries estimate = random_poses(50, 1);
  const PoseSeries reference = apply_similarity(estimate, 2.5, kRotation, kTranslation);
  PoseSeries aligned = estimate;
  const Similarity sim = align_estimate(aligned, reference, AlignmentMode::kSim3);
  EXPECT_NEAR(sim.scale, 2.5, 1e-12);
  EXPECT_LT((sim.R - kRotation).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((sim.t - kTranslation).cwiseAbs().maxCoeff(), 1e-11);
  expect_poses_near(aligned, reference, 1e-11);
}

TEST(Umeyama, Se3RecoversRotationAndTranslationWithoutScale) {
  const PoseSeries estimate = random_poses(30, 2);
  const PoseSeries reference = apply_similarity(estimate, 1.0, kRotation, kTranslation);
  PoseSeries aligned = estimate;
  const Similarity sim = align_estimate(aligned, reference, AlignmentMode::kSe3);
  EXPECT_EQ(sim.scale, 1.0);
  EXPECT_LT((sim.R - kRotation).cwiseAbs().maxCoeff(), 1e-12);
  expect_poses_near(aligned, reference, 1e-11);
}

TEST(Umeyama, Se3DoesNotCorrectScale) {
  const PoseSeries estimate = random_poses(30, 3);
  const PoseSeries reference = apply_similarity(estimate, 3.0, kRotation, kTranslation);
  PoseSeries aligned = estimate;
  align_estimate(aligned, reference, AlignmentMode::kSe3);
  double worst = 0.0;
  for (std::size_t i = 0; i < aligned.size(); ++i)
    worst = std::max(worst, (aligned.poses[i] - reference.poses[i]).norm());
  EXPECT_GT(worst, 1.0);
}

TEST(Umeyama, ScaleOnlyScalesPositionsAndKeepsRotations) {
  const PoseSeries estimate = random_poses(30, 4);
  // The reference is the estimate scaled about the origin: scale-only alignment recovers it.
  const PoseSeries reference = apply_similarity(estimate, 0.4, Mat3::Identity(), Vec3::Zero());
  PoseSeries aligned = estimate;
  const Similarity sim = align_estimate(aligned, reference, AlignmentMode::kScale);
  EXPECT_NEAR(sim.scale, 0.4, 1e-12);
  expect_poses_near(aligned, reference, 1e-12);
  for (std::size_t i = 0; i < aligned.size(); ++i)
    EXPECT_TRUE(
        (aligned.poses[i].topLeftCorner<3, 3>() == estimate.poses[i].topLeftCorner<3, 3>()));
}

TEST(Umeyama, NToAlignUsesOnlyTheFirstPoses) {
  const PoseSeries estimate = random_poses(40, 5);
  PoseSeries reference = apply_similarity(estimate, 1.7, kRotation, kTranslation);
  // Corrupt the tail: an alignment on the first 10 poses must not see it.
  for (std::size_t i = 10; i < reference.size(); ++i) reference.poses[i](0, 3) += 3.0;

  PoseSeries aligned_head = estimate;
  const Similarity head =
      align_estimate(aligned_head, reference, AlignmentMode::kSim3, std::size_t{10});
  EXPECT_NEAR(head.scale, 1.7, 1e-12);
  EXPECT_LT((head.R - kRotation).cwiseAbs().maxCoeff(), 1e-12);

  PoseSeries aligned_all = estimate;
  const Similarity all = align_estimate(aligned_all, reference, AlignmentMode::kSim3);
  EXPECT_GT((all.t - kTranslation).norm(), 1e-3);
}

TEST(Umeyama, NoneLeavesTheEstimateUnchanged) {
  const PoseSeries estimate = random_poses(5, 6);
  PoseSeries aligned = estimate;
  align_estimate(aligned, random_poses(5, 7), AlignmentMode::kNone);
  expect_poses_near(aligned, estimate, 0.0);
}

TEST(Umeyama, RefusesDegenerateAndTooFewPositions) {
  PoseSeries collinear;
  for (int i = 0; i < 5; ++i) {
    Mat4 T = Mat4::Identity();
    T(0, 3) = i;
    collinear.stamps.push_back(i);
    collinear.poses.push_back(T);
  }
  PoseSeries aligned = collinear;
  EXPECT_THROW(align_estimate(aligned, collinear, AlignmentMode::kSe3), Error);
  const PoseSeries estimate = random_poses(5, 8);
  aligned = estimate;
  EXPECT_THROW(align_estimate(aligned, estimate, AlignmentMode::kSe3, std::size_t{1}), Error);
  EXPECT_THROW(align_estimate(aligned, estimate, AlignmentMode::kSe3, std::size_t{6}), Error);
}

TEST(AlignmentMode, ParsesNamesAndRefusesOthers) {
  EXPECT_EQ(parse_alignment_mode("sim3"), AlignmentMode::kSim3);
  EXPECT_EQ(parse_alignment_mode("scale"), AlignmentMode::kScale);
  EXPECT_EQ(alignment_mode_name(parse_alignment_mode("se3")), "se3");
  EXPECT_THROW(parse_alignment_mode("SE3x"), Error);
}

}  // namespace
}  // namespace sbaslam::eval
