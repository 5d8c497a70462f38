#pragma once
// A mip-mapped grayscale texture. Distant or grazing surfaces read a coarser level chosen from the
// pixel's footprint in texels, and two levels are blended (trilinear filtering), so far surfaces
// average their texels instead of aliasing into fake corners that a FAST detector would pick up.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

namespace sbaslam::sim {

enum class TextureWrap { kRepeat, kClamp };

class Texture {
 public:
  // base: CV_8UC1 whose width and height are powers of two.
  Texture(const cv::Mat& base, TextureWrap wrap);

  int width() const { return levels_.front().cols; }
  int height() const { return levels_.front().rows; }
  int level_count() const { return static_cast<int>(levels_.size()); }
  TextureWrap wrap() const { return wrap_; }
  const cv::Mat& level(int i) const { return levels_[static_cast<std::size_t>(i)]; }

  // Value in [0, 255] at level-0 texel coordinates (u, v), texel k covering [k, k + 1).
  // lod is log2 of the pixel footprint in level-0 texels; <= 0 means magnification. Trilinear:
  // two levels blended by the fraction of lod. Inline: the renderer calls it once per pixel.
  float sample(double u, double v, float lod) const {
    const std::int64_t fu = to_fixed(u), fv = to_fixed(v);
    const float clamped = std::min(std::max(lod, 0.0f), last_level_);
    const int l0 = static_cast<int>(clamped);
    const float t = clamped - static_cast<float>(l0);
    const float a = bilinear_fixed(l0, fu, fv);
    if (t == 0.0f) return a;  // magnification, the coarsest level, or exactly on a level
    // t > 0 implies clamped < last level, so level l0 + 1 exists.
    const float b = bilinear_fixed(l0 + 1, fu, fv);
    return a + t * (b - a);
  }
  // Bilinear value of one level, at level-0 texel coordinates.
  float bilinear(int level, double u, double v) const {
    return bilinear_fixed(level, to_fixed(u), to_fixed(v));
  }

 private:
  // Texel coordinates in fixed point: one conversion per pixel serves both mip levels (a level's
  // coordinate is a shift), and the texel index and weight are a shift and a mask.
  static constexpr int kFractionBits = 16;
  static constexpr std::int64_t kOne = std::int64_t{1} << kFractionBits;
  // World textures stay below 2^16 texels from their origin (ground planes of a few hundred
  // metres); the clamp only keeps the conversion defined for anything further out.
  static std::int64_t to_fixed(double texels) {
    const double clamped = std::min(std::max(texels, -60000.0), 60000.0);
    return static_cast<std::int64_t>(clamped * static_cast<double>(kOne));
  }
  float bilinear_fixed(int level, std::int64_t fu, std::int64_t fv) const {
    const LevelView& L = views_[static_cast<std::size_t>(level)];
    // Level texel centres sit at half a texel: subtract 0.5 level texels (arithmetic shifts
    // floor, also for negative coordinates).
    const std::int64_t x = (fu >> level) - kOne / 2;
    const std::int64_t y = (fv >> level) - kOne / 2;
    const int xi = static_cast<int>(x >> kFractionBits);
    const int yi = static_cast<int>(y >> kFractionBits);
    const std::int64_t ax = x & (kOne - 1), ay = y & (kOne - 1);
    int x0, x1, y0, y1;
    if (wrap_ == TextureWrap::kRepeat) {
      x0 = xi & L.mask_x;
      x1 = (xi + 1) & L.mask_x;
      y0 = yi & L.mask_y;
      y1 = (yi + 1) & L.mask_y;
    } else {
      x0 = std::clamp(xi, 0, L.mask_x);
      x1 = std::clamp(xi + 1, 0, L.mask_x);
      y0 = std::clamp(yi, 0, L.mask_y);
      y1 = std::clamp(yi + 1, 0, L.mask_y);
    }
    const std::uint8_t* r0 = L.data + static_cast<std::ptrdiff_t>(y0) * L.stride;
    const std::uint8_t* r1 = L.data + static_cast<std::ptrdiff_t>(y1) * L.stride;
    // Exact integer interpolation with 16-bit weights, one rounding to float at the end.
    const std::int64_t top = (std::int64_t{r0[x0]} << kFractionBits) + ax * (r0[x1] - r0[x0]);
    const std::int64_t bottom = (std::int64_t{r1[x0]} << kFractionBits) + ax * (r1[x1] - r1[x0]);
    const std::int64_t value = (top << kFractionBits) + ay * (bottom - top);
    return static_cast<float>(value) * (1.0f / static_cast<float>(kOne * kOne));
  }

  struct LevelView {
    const std::uint8_t* data;
    std::ptrdiff_t stride;
    int mask_x, mask_y;  // size - 1 (sizes are powers of two)
  };
  std::vector<cv::Mat> levels_;
  std::vector<LevelView> views_;
  TextureWrap wrap_;
  float last_level_ = 0.0f;  // index of the 1x1 level
};

// log2(x) for x > 0 with an error below 0.09, monotonic and continuous: good enough to pick a mip
// level and several times cheaper than std::log2.
inline float fast_log2(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof(bits));
  const float exponent = static_cast<float>(static_cast<int>((bits >> 23) & 0xFF) - 127);
  const float mantissa = static_cast<float>(bits & 0x7FFFFF) * (1.0f / 8388608.0f);
  return exponent + mantissa;
}

}  // namespace sbaslam::sim
