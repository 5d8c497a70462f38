#include "sbaslam/eval/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

TEST(ComputeStatistics, EvenCountLikeNumpy) {
  const ErrorStatistics s = compute_statistics({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.n, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);  // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std (numpy's default)
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
}

TEST(ComputeStatistics, OddCountMedianIsTheMiddleValue) {
  const ErrorStatistics s = compute_statistics({10.0, 0.5, 2.0});
  EXPECT_EQ(s.median, 2.0);
  EXPECT_DOUBLE_EQ(s.mean, 12.5 / 3.0);
}

TEST(ComputeStatistics, RefusesEmptyAndNonFinite) {
  EXPECT_THROW(compute_statistics({}), Error);
  EXPECT_THROW(compute_statistics({1.0, std::numeric_limits<double>::quiet_NaN()}), Error);
  EXPECT_THROW(compute_statistics({std::numeric_limits<double>::infinity()}), Error);
}

}  // namespace
}  // namespace sbaslam::eval
