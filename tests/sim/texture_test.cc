// The fixed-point texture sampler against a plain double-precision trilinear filter written from
// the definition: texel k covers [k, k + 1), level l has texels 2^l times larger, repeat wraps
// and clamp holds the border, and lod blends the two levels around it.

#include "sbaslam/sim/texture.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sbaslam/core/error.h"
#include "sbaslam/sim/random.h"

namespace sbaslam::sim {
namespace {

double reference_bilinear(const Texture& tex, int level, double u, double v) {
  const cv::Mat& m = tex.level(level);
  const double scale = std::ldexp(1.0, -level);
  const double x = u * scale - 0.5, y = v * scale - 0.5;
  const int xi = static_cast<int>(std::floor(x)), yi = static_cast<int>(std::floor(y));
  auto at = [&](int row, int col) {
    if (tex.wrap() == TextureWrap::kRepeat) {
      row = ((row % m.rows) + m.rows) % m.rows;
      col = ((col % m.cols) + m.cols) % m.cols;
    } else {
      row = std::clamp(row, 0, m.rows - 1);
      col = std::clamp(col, 0, m.cols - 1);
    }
    return static_cast<double>(m.at<std::uint8_t>(row, col));
  };
  const double ax = x - xi, ay = y - yi;
  const double top = at(yi, xi) + ax * (at(yi, xi + 1) - at(yi, xi));
  const double bottom = at(yi + 1, xi) + ax * (at(yi + 1, xi + 1) - at(yi + 1, xi));
  return top + ay * (bottom - top);
}

double reference_sample(const Texture& tex, double u, double v, double lod) {
  const int last = tex.level_count() - 1;
  if (lod <= 0.0) return reference_bilinear(tex, 0, u, v);
  if (lod >= last) return reference_bilinear(tex, last, u, v);
  const int l0 = static_cast<int>(std::floor(lod));
  const double t = lod - l0;
  return (1.0 - t) * reference_bilinear(tex, l0, u, v) + t * reference_bilinear(tex, l0 + 1, u, v);
}

cv::Mat random_image(int width, int height, std::uint64_t seed) {
  Random rng(seed);
  cv::Mat m(height, width, CV_8U);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      m.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(rng.integer(0, 255));
  return m;
}

void expect_matches_reference(const Texture& tex, std::uint64_t seed) {
  Random rng(seed);
  for (int i = 0; i < 20000; ++i) {
    // Far outside the texture too (negative coordinates, many repeats), and lods below 0 and
    // beyond the coarsest level.
    const double u = rng.uniform(-3000.0, 3000.0), v = rng.uniform(-3000.0, 3000.0);
    const float lod = static_cast<float>(rng.uniform(-2.0, tex.level_count() + 1.0));
    const double expected = reference_sample(tex, u, v, lod);
    ASSERT_NEAR(tex.sample(u, v, lod), expected, 0.02) << "u " << u << " v " << v << " lod " << lod;
  }
}

TEST(SimTexture, RepeatSamplingMatchesTrilinearReference) {
  expect_matches_reference(Texture(random_image(64, 32, 1), TextureWrap::kRepeat), 2);
}

TEST(SimTexture, ClampSamplingMatchesTrilinearReference) {
  expect_matches_reference(Texture(random_image(32, 128, 3), TextureWrap::kClamp), 4);
}

TEST(SimTexture, TexelCentresReturnTheTexel) {
  const cv::Mat image = random_image(16, 16, 5);
  const Texture tex(image, TextureWrap::kRepeat);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      EXPECT_EQ(tex.sample(x + 0.5, y + 0.5, -1.0f), image.at<std::uint8_t>(y, x));
  // The 1x1 level is the mean of the image, whatever the coordinates.
  EXPECT_NEAR(tex.sample(123.4, -56.7, 30.0f), cv::mean(image)[0], 2.0);
}

TEST(SimTexture, RejectsSizesThatAreNotPowersOfTwo) {
  EXPECT_THROW(Texture(cv::Mat(48, 64, CV_8U, cv::Scalar(0)), TextureWrap::kRepeat), Error);
  EXPECT_THROW(Texture(cv::Mat(), TextureWrap::kRepeat), Error);
}

}  // namespace
}  // namespace sbaslam::sim
