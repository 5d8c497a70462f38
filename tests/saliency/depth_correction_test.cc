// Algorithm 1's depth correction on known maps, and the three depth sources.

#include "sbaslam/saliency/depth_correction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <tuple>

#include "sbaslam/core/error.h"

namespace sbaslam::saliency {
namespace {

TEST(DepthCorrection, EqualsTheFormulaWithMaxNormalisationAndMedianFallback) {
  const cv::Mat s = (cv::Mat_<std::uint8_t>(2, 3) << 255, 102, 51, 204, 0, 153);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Valid depths 2, 4, 5, 10 (median of the four: the upper middle, 5); 0 and NaN are invalid.
  const cv::Mat d = (cv::Mat_<float>(2, 3) << 2.0f, 4.0f, 0.0f, 10.0f, 5.0f, nan);
  const double a = 2.0, b = 0.1;
  const double s_hat[6] = {a * 1.0 / 2 + b,  a * 0.4 / 4 + b, a * 0.2 / 5 + b,
                           a * 0.8 / 10 + b, a * 0.0 / 5 + b, a * 0.6 / 5 + b};
  const cv::Mat out = depth_corrected_saliency(s, d, a, b);
  ASSERT_EQ(out.type(), CV_8UC1);
  ASSERT_EQ(out.size(), s.size());
  const double peak = s_hat[0];  // 1.1
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(out.at<std::uint8_t>(i / 3, i % 3), 255.0 * s_hat[i] / peak, 0.5001) << i;
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 255);
}

TEST(DepthCorrection, DepthsBelowTheNearDepthCountAsIt) {
  const cv::Mat s(1, 4, CV_8U, cv::Scalar(255));
  const cv::Mat d = (cv::Mat_<float>(1, 4) << 1.0f, 4.0f, 8.0f, 16.0f);
  // D = max(D, 8): the first three pixels all count as 8 m and share the peak.
  const cv::Mat out = depth_corrected_saliency(s, d, 1.0, 0.0, 8.0);
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 255);
  EXPECT_EQ(out.at<std::uint8_t>(0, 1), 255);
  EXPECT_EQ(out.at<std::uint8_t>(0, 2), 255);
  EXPECT_NEAR(out.at<std::uint8_t>(0, 3), 127.5, 0.5001);
  // Without it the paper's plain 1 / D ranks all four.
  const cv::Mat plain = depth_corrected_saliency(s, d, 1.0, 0.0);
  EXPECT_NEAR(plain.at<std::uint8_t>(0, 1), 63.75, 0.5001);
}

TEST(DepthCorrection, SaturationTurnsTheMapIntoASoftMask) {
  const cv::Mat s = (cv::Mat_<std::uint8_t>(1, 5) << 0, 2, 5, 10, 255);
  const cv::Mat out = saturated_saliency(s, 0.02);  // 5.1 grey levels and above become 255
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 0);
  EXPECT_EQ(out.at<std::uint8_t>(0, 1), 100);
  EXPECT_EQ(out.at<std::uint8_t>(0, 2), 250);
  EXPECT_EQ(out.at<std::uint8_t>(0, 3), 255);
  EXPECT_EQ(out.at<std::uint8_t>(0, 4), 255);
  EXPECT_EQ(cv::norm(saturated_saliency(s, 1.0), s, cv::NORM_INF), 0.0);
  EXPECT_THROW(saturated_saliency(s, 0.0), Error);
  EXPECT_THROW(saturated_saliency(s, 1.5), Error);
}

TEST(DepthCorrection, NearerIsMoreSalientAndDepthIsResampled) {
  const cv::Mat s(4, 8, CV_8U, cv::Scalar(200));
  cv::Mat d(2, 4, CV_32F, cv::Scalar(20.0f));
  d.at<float>(0, 0) = 2.0f;  // covers the map's top-left 2x2 block after nearest resampling
  const cv::Mat out = depth_corrected_saliency(s, d, 1.0, 0.0);
  EXPECT_EQ(out.at<std::uint8_t>(1, 1), 255);
  EXPECT_NEAR(out.at<std::uint8_t>(3, 7), 25.5, 0.6);
}

TEST(DepthCorrection, NoValidDepthKeepsTheInitialMap) {
  const cv::Mat s = (cv::Mat_<std::uint8_t>(1, 3) << 10, 20, 30);
  const cv::Mat out = depth_corrected_saliency(s, cv::Mat(1, 3, CV_32F, cv::Scalar(0)), 1.0, 0.0);
  EXPECT_EQ(cv::norm(out, s, cv::NORM_INF), 0.0);
  EXPECT_THROW(depth_corrected_saliency(s, cv::Mat(1, 3, CV_8U), 1.0, 0.0), Error);
}

TEST(DepthCorrection, DensifiedSparseDepthInterpolatesBetweenSamples) {
  std::vector<DepthSample> samples;
  for (int v = 8; v < 64; v += 16) {
    samples.push_back({8.0f, float(v), 4.0f});    // left column at 4 m
    samples.push_back({120.0f, float(v), 8.0f});  // right column at 8 m
  }
  const cv::Mat dense = densify_sparse_depth(samples, cv::Size(128, 64), 16, 4);
  ASSERT_EQ(dense.size(), cv::Size(128, 64));
  EXPECT_NEAR(dense.at<float>(32, 8), 4.0f, 1e-4);
  EXPECT_NEAR(dense.at<float>(32, 120), 8.0f, 1e-4);
  const float middle = dense.at<float>(32, 64);
  EXPECT_GT(middle, 4.5f);
  EXPECT_LT(middle, 7.5f);
  for (int x = 8; x + 8 < 120; x += 8)  // monotone from left to right
    EXPECT_LE(dense.at<float>(32, x), dense.at<float>(32, x + 8) + 1e-5f);
  EXPECT_EQ(cv::countNonZero(densify_sparse_depth({}, cv::Size(8, 8))), 0);
}

// The definition, by brute force over every filled cell: the k nearest (ties by row, then
// column), weighted by inverse squared distance.
float nearest_cells_depth(const std::vector<DepthSample>& filled, int x, int y, std::size_t k) {
  std::vector<std::tuple<int, int, int, float>> by_distance;  // squared distance, row, col, depth
  for (const DepthSample& s : filled) {
    const int dx = int(s.u) - x, dy = int(s.v) - y;
    by_distance.emplace_back(dx * dx + dy * dy, int(s.v), int(s.u), s.depth);
  }
  std::sort(by_distance.begin(), by_distance.end());
  double weighted = 0.0, weights = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    weighted += std::get<3>(by_distance[i]) / std::get<0>(by_distance[i]);
    weights += 1.0 / std::get<0>(by_distance[i]);
  }
  return float(weighted / weights);
}

TEST(DepthCorrection, EmptyCellsTakeTheInverseDistanceMeanOfTheNearestFilledCells) {
  // One-pixel cells (no upsampling), sparse random samples on a 40x24 grid, ties included.
  const cv::Size size(40, 24);
  std::mt19937 rng(5);
  std::vector<DepthSample> samples;
  cv::Mat taken(size, CV_8U, cv::Scalar(0));
  while (samples.size() < 25) {
    const int x = int(rng() % 40), y = int(rng() % 24);
    if (taken.at<std::uint8_t>(y, x)) continue;
    taken.at<std::uint8_t>(y, x) = 1;
    samples.push_back({float(x), float(y), 1.0f + float(rng() % 1000) / 50.0f});
  }
  for (std::size_t k : {1u, 4u, 7u}) {
    const cv::Mat dense = densify_sparse_depth(samples, size, 1, int(k));
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        if (taken.at<std::uint8_t>(y, x)) continue;
        ASSERT_NEAR(dense.at<float>(y, x), nearest_cells_depth(samples, x, y, k), 1e-5)
            << "k " << k << " at " << x << "," << y;
      }
  }
}

TEST(DepthCorrection, KeypointDepthsScaleToTheMapAndFavourNearKeypoints) {
  // A uniform 80x24 map over a 1240x372 image: keypoints on the left half at 5 m, on the right
  // half at 20 m. After correction (a = 1, b = 0) the left half is 4x as salient as the right.
  const cv::Mat s(24, 80, CV_8U, cv::Scalar(255));
  std::vector<DepthSample> keypoints;
  for (float v = 10.0f; v < 372.0f; v += 30.0f)
    for (float u = 10.0f; u < 1240.0f; u += 40.0f)
      keypoints.push_back({u, v, u < 620.0f ? 5.0f : 20.0f});
  const cv::Mat out = depth_corrected_saliency(s, cv::Size(1240, 372), keypoints, 1.0, 0.0);
  ASSERT_EQ(out.size(), s.size());
  EXPECT_EQ(out.at<std::uint8_t>(12, 5), 255);
  EXPECT_NEAR(out.at<std::uint8_t>(12, 75), 255.0 / 4.0, 1.0);
  EXPECT_THROW(depth_corrected_saliency(s, cv::Size(0, 0), keypoints, 1.0, 0.0), Error);
}

TEST(DepthCorrection, StereoDepthOfAKnownDisparity) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> grey(0, 255);
  cv::Mat texture(120, 220, CV_8U);
  for (int y = 0; y < texture.rows; ++y)
    for (int x = 0; x < texture.cols; ++x) texture.at<std::uint8_t>(y, x) = grey(rng);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
  const int disparity = 10;
  // Texture column c is at x = c in the left image and at x = c - 10 in the right one.
  const cv::Mat left = texture(cv::Rect(0, 0, 200, 120)).clone();
  const cv::Mat right = texture(cv::Rect(disparity, 0, 200, 120)).clone();
  const double fx = 500.0, baseline = 0.2;
  const cv::Mat depth = stereo_depth(left, right, fx, baseline, 64);
  std::vector<float> valid;
  for (int y = 10; y < 110; ++y)
    for (int x = 80; x < 190; ++x)
      if (depth.at<float>(y, x) > 0) valid.push_back(depth.at<float>(y, x));
  ASSERT_GT(valid.size(), 5000u);
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  EXPECT_NEAR(valid[valid.size() / 2], fx * baseline / disparity, 0.05);
}

TEST(DepthCorrection, RgbdDepthDividesByTheFactor) {
  const cv::Mat raw = (cv::Mat_<std::uint16_t>(1, 2) << 5000, 0);
  const cv::Mat d = rgbd_depth(raw, 5000.0);
  EXPECT_FLOAT_EQ(d.at<float>(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(d.at<float>(0, 1), 0.0f);
  EXPECT_THROW(rgbd_depth(raw, 0.0), Error);
}

}  // namespace
}  // namespace sbaslam::saliency
