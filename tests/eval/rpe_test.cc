#include "sbaslam/eval/rpe.h"

#include <gtest/gtest.h>

#include "sbaslam/core/error.h"
#include "sbaslam/eval/ape.h"

namespace sbaslam::eval {
namespace {

std::vector<Mat4> poses_along_x(const std::vector<double>& xs) {
  std::vector<Mat4> poses;
  for (double x : xs) {
    Mat4 T = Mat4::Identity();
    T(0, 3) = x;
    poses.push_back(T);
  }
  return poses;
}

using Pairs = std::vector<IdPair>;

TEST(SelectPairs, FramesConsecutive) {
  const auto poses = poses_along_x({0, 1, 2, 3, 4, 5, 6});
  EXPECT_EQ(select_pairs(poses, {2.0, DeltaUnit::kFrames, false}), (Pairs{{0, 2}, {2, 4}, {4, 6}}));
  EXPECT_EQ(select_pairs(poses, {3.0, DeltaUnit::kFrames, false}), (Pairs{{0, 3}, {3, 6}}));
  EXPECT_TRUE(select_pairs(poses, {7.0, DeltaUnit::kFrames, false}).empty());
}

TEST(SelectPairs, FramesAllPairs) {
  const auto poses = poses_along_x({0, 1, 2, 3, 4});
  EXPECT_EQ(select_pairs(poses, {2.0, DeltaUnit::kFrames, true}), (Pairs{{0, 2}, {1, 3}, {2, 4}}));
}

// Steps 1, 1.5, 0.5, 2, 0.5, 1.5: accumulated path 0, 1, 2.5, 3, 5, 5.5, 7.
const std::vector<double> kXs = {0, 1, 2.5, 3, 5, 5.5, 7};

TEST(SelectPairs, MetresConsecutiveResetsAtEachRecordedPose) {
  // Path reaches 2 at index 2 (2.5), then 2.5 more at index 4, then 2.0 at index 6.
  EXPECT_EQ(select_pairs(poses_along_x(kXs), {2.0, DeltaUnit::kMeters, false}),
            (Pairs{{2, 4}, {4, 6}}));
}

TEST(SelectPairs, MetresAllPairsKeepsClosestWithinTolerance) {
  // tol = 0.1 * 2 = 0.2: from 0 the best is 2.5 (off by 0.5, dropped); from 1 exactly 2 at 3;
  // from 2 the best is off by 0.5; from 3 exactly 2 at 4; from 4 exactly 2 at 6; from 5, 0.5 off.
  EXPECT_EQ(select_pairs(poses_along_x(kXs), {2.0, DeltaUnit::kMeters, true, 0.1}),
            (Pairs{{1, 3}, {3, 4}, {4, 6}}));
  // A loose tolerance keeps every start.
  EXPECT_EQ(select_pairs(poses_along_x(kXs), {2.0, DeltaUnit::kMeters, true, 1.0}).size(), 6u);
}

TEST(SelectPairs, RefusesInvalidDeltas) {
  const auto poses = poses_along_x({0, 1, 2});
  EXPECT_THROW(select_pairs(poses, {0.0, DeltaUnit::kFrames, false}), Error);
  EXPECT_THROW(select_pairs(poses, {1.5, DeltaUnit::kFrames, false}), Error);
  EXPECT_THROW(select_pairs(poses, {-2.0, DeltaUnit::kMeters, false}), Error);
  EXPECT_THROW(parse_delta_unit("km"), Error);
  EXPECT_EQ(parse_delta_unit("m"), DeltaUnit::kMeters);
}

PoseSeries random_walk(std::size_t n) {
  PoseSeries series;
  SE3 pose;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = static_cast<double>(i);
    pose = pose * SE3(SO3::exp(Vec3(0.01 * a, 0.05, -0.02)), Vec3(1.0, 0.1 * a, 0.2));
    series.stamps.push_back(a);
    series.poses.push_back(pose.matrix());
  }
  return series;
}

TEST(RelativePoseErrors, IgnoreAGlobalTransformThatApeSees) {
  const PoseSeries reference = random_walk(20);
  PoseSeries estimate = reference;
  const Mat4 offset = SE3(SO3::exp(Vec3(0.2, 0.1, -0.3)), Vec3(5.0, 1.0, 2.0)).matrix();
  for (Mat4& pose : estimate.poses) pose = offset * pose;

  const auto pairs = select_pairs(estimate.poses, {1.0, DeltaUnit::kFrames, false});
  for (double e : relative_pose_errors(reference, estimate, pairs, PoseRelation::kTransPart))
    EXPECT_LT(e, 1e-12);
  for (double e : relative_pose_errors(reference, estimate, pairs, PoseRelation::kAngleDeg))
    EXPECT_LT(e, 1e-6);
  for (double e : absolute_pose_errors(reference, estimate, PoseRelation::kTransPart))
    EXPECT_GT(e, 0.1);
}

TEST(RelativePoseErrors, MeasureALocalPerturbation) {
  const PoseSeries reference = random_walk(5);
  PoseSeries estimate = reference;
  // Move pose 3 by 0.25 m along its own x axis and turn it by 0.1 rad about its z axis.
  const Mat4 local = SE3(SO3::exp(Vec3(0.0, 0.0, 0.1)), Vec3(0.25, 0.0, 0.0)).matrix();
  estimate.poses[3] = estimate.poses[3] * local;
  const Pairs pairs = {{2, 3}, {3, 4}, {0, 1}};
  const auto trans = relative_pose_errors(reference, estimate, pairs, PoseRelation::kTransPart);
  EXPECT_NEAR(trans[0], 0.25, 1e-12);
  // For (3, 4): E = inv(Q_rel) inv(L) Q_rel, computed here with the SE3 class.
  const SE3 Q_rel = SE3::from_matrix(Mat4(se3_inverse(reference.poses[3]) * reference.poses[4]));
  const SE3 L = SE3::from_matrix(local);
  const SE3 E = Q_rel.inverse() * L.inverse() * Q_rel;
  EXPECT_NEAR(trans[1], E.translation().norm(), 1e-12);
  EXPECT_GT(trans[1], 0.1);
  EXPECT_NEAR(trans[2], 0.0, 1e-12);
  const auto angle = relative_pose_errors(reference, estimate, pairs, PoseRelation::kAngleRad);
  EXPECT_NEAR(angle[0], 0.1, 1e-12);
  EXPECT_NEAR(angle[1], 0.1, 1e-12);
  EXPECT_NEAR(angle[2], 0.0, 1e-12);
}

}  // namespace
}  // namespace sbaslam::eval
