#include "sbaslam/eval/association.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

// Poses whose x position is the row index, so a kept pose tells which row it came from.
PoseSeries series_with_stamps(const std::vector<double>& stamps) {
  PoseSeries series;
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    Mat4 T = Mat4::Identity();
    T(0, 3) = static_cast<double>(i);
    series.stamps.push_back(stamps[i]);
    series.poses.push_back(T);
  }
  return series;
}

using Ids = std::vector<std::size_t>;

TEST(AssociateByTime, ShorterEstimatePicksNearestReferenceWithinMaxDiff) {
  const PoseSeries reference = series_with_stamps({0.0, 0.1, 0.2, 0.3, 0.4});
  const PoseSeries estimate = series_with_stamps({0.098, 0.25, 0.305});
  const AssociatedSeries paired = associate_by_time(reference, estimate, {0.01, 0.0});
  // 0.25 is 0.05 from both neighbours: dropped.
  EXPECT_EQ(paired.estimate_ids, (Ids{0, 2}));
  EXPECT_EQ(paired.reference_ids, (Ids{1, 3}));
  EXPECT_EQ(paired.reference.poses[1](0, 3), 3.0);
  EXPECT_EQ(paired.estimate.stamps, (std::vector<double>{0.098, 0.305}));
}

TEST(AssociateByTime, EqualLengthsIterateOverTheEstimateLikeEvo) {
  // Over the estimate: 0.0 -> 0, 0.004 -> 0, 0.2 -> 2 (three pairs, reference row 0 twice).
  // Over the reference it would be two pairs.
  const PoseSeries reference = series_with_stamps({0.0, 0.1, 0.2});
  const PoseSeries estimate = series_with_stamps({0.0, 0.004, 0.2});
  const AssociatedSeries paired = associate_by_time(reference, estimate, {0.01, 0.0});
  EXPECT_EQ(paired.estimate_ids, (Ids{0, 1, 2}));
  EXPECT_EQ(paired.reference_ids, (Ids{0, 0, 2}));
}

TEST(AssociateByTime, LongerEstimateIteratesOverTheReference) {
  const PoseSeries reference = series_with_stamps({0.0, 0.2});
  const PoseSeries estimate = series_with_stamps({0.0, 0.003, 0.1, 0.199});
  const AssociatedSeries paired = associate_by_time(reference, estimate, {0.01, 0.0});
  EXPECT_EQ(paired.reference_ids, (Ids{0, 1}));
  EXPECT_EQ(paired.estimate_ids, (Ids{0, 3}));
}

TEST(AssociateByTime, TiesTakeTheFirstIndex) {
  const PoseSeries reference = series_with_stamps({0.0, 0.5, 1.0, 1.5});
  const PoseSeries estimate = series_with_stamps({0.25, 1.0});
  const AssociatedSeries paired = associate_by_time(reference, estimate, {0.25, 0.0});
  EXPECT_EQ(paired.reference_ids, (Ids{0, 2}));
}

TEST(AssociateByTime, OffsetIsAddedToTheEstimateStamps) {
  const PoseSeries reference = series_with_stamps({10.0, 11.0, 12.0, 13.0});
  const PoseSeries estimate = series_with_stamps({0.0, 1.0, 2.0});
  const AssociatedSeries shifted = associate_by_time(reference, estimate, {0.01, 11.0});
  EXPECT_EQ(shifted.reference_ids, (Ids{1, 2, 3}));
  EXPECT_EQ(shifted.estimate_ids, (Ids{0, 1, 2}));
  // The same offset when the estimate is the longer series (evo negates it on the reference).
  const AssociatedSeries swapped = associate_by_time(estimate, reference, {0.01, -11.0});
  EXPECT_EQ(swapped.reference_ids, (Ids{0, 1, 2}));
  EXPECT_EQ(swapped.estimate_ids, (Ids{1, 2, 3}));
}

TEST(AssociateByTime, NoOverlapInTimeIsRefused) {
  const PoseSeries reference = series_with_stamps({0.0, 1.0, 2.0});
  const PoseSeries estimate = series_with_stamps({100.0, 101.0});
  try {
    associate_by_time(reference, estimate, {0.01, 0.0});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no overlap in time"), std::string::npos) << e.what();
  }
}

TEST(AssociateByTime, OverlapWithoutCloseStampsIsRefused) {
  const PoseSeries reference = series_with_stamps({0.0, 1.0, 2.0});
  const PoseSeries estimate = series_with_stamps({0.5, 1.5});
  try {
    associate_by_time(reference, estimate, {0.01, 0.0});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no matching timestamps"), std::string::npos) << e.what();
  }
}

TEST(AssociateByTime, NanIsRefused) {
  PoseSeries reference = series_with_stamps({0.0, 1.0, 2.0});
  const PoseSeries estimate = series_with_stamps({0.0, 1.0});
  reference.poses[1](1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(associate_by_time(reference, estimate, {0.01, 0.0}), Error);
  EXPECT_THROW(associate_by_time(estimate, estimate, {std::nan(""), 0.0}), Error);
}

TEST(AssociateByIndex, PairsRowByRowAndNeedsEqualLengths) {
  const PoseSeries a = series_with_stamps({0.0, 1.0, 2.0});
  const PoseSeries b = series_with_stamps({5.0, 6.0, 7.0});
  const AssociatedSeries paired = associate_by_index(a, b);
  EXPECT_EQ(paired.reference_ids, (Ids{0, 1, 2}));
  EXPECT_EQ(paired.estimate.stamps, b.stamps);
  const PoseSeries shorter = series_with_stamps({0.0, 1.0});
  EXPECT_THROW(associate_by_index(a, shorter), Error);
}

}  // namespace
}  // namespace sbaslam::eval
