#include "sbaslam/sim/texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam::sim {
namespace {

bool is_power_of_two(int n) {
  return n > 0 && (n & (n - 1)) == 0;
}

// Exact 2x2 box averaging keeps a repeating texture repeating at every level.
cv::Mat halve(const cv::Mat& level) {
  const int w = std::max(1, level.cols / 2);
  const int h = std::max(1, level.rows / 2);
  cv::Mat out;
  cv::resize(level, out, cv::Size(w, h), 0.0, 0.0, cv::INTER_AREA);
  return out;
}

}  // namespace

Texture::Texture(const cv::Mat& base, TextureWrap wrap) : wrap_(wrap) {
  if (base.empty() || base.type() != CV_8UC1) fail("texture: expected a non-empty 8-bit image");
  if (!is_power_of_two(base.cols) || !is_power_of_two(base.rows))
    fail("texture: size {}x{} is not a power of two", base.cols, base.rows);
  levels_.push_back(base.clone());
  while (levels_.back().cols > 1 || levels_.back().rows > 1)
    levels_.push_back(halve(levels_.back()));
  for (std::size_t i = 0; i < levels_.size(); ++i) {
    const cv::Mat& m = levels_[i];
    views_.push_back(
        {m.ptr<std::uint8_t>(), static_cast<std::ptrdiff_t>(m.step[0]), m.cols - 1, m.rows - 1});
  }
  last_level_ = static_cast<float>(levels_.size() - 1);
}

}  // namespace sbaslam::sim
