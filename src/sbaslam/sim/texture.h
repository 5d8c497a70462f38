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
  // lod is log2 of the pixel footprint in level-0 texels; <= 0 means magnification.
  // Inline: the renderer calls it once per pixel.
  float sample(double u, double v, float lod) const {
    if (lod <= 0.0f) return bilinear(0, u, v);
    const int last = static_cast<int>(views_.size()) - 1;
    const int l0 = static_cast<int>(lod);
    if (l0 >= last) return bilinear(last, u, v);
    const float t = lod - static_cast<float>(l0);
    const float a = bilinear(l0, u, v);
    const float b = bilinear(l0 + 1, u, v);
    return a + t * (b - a);
  }
  // Bilinear value of one level, at level-0 texel coordinates.
  float bilinear(int level, double u, double v) const {
    const LevelView& L = views_[static_cast<std::size_t>(level)];
    // Float is exact enough: world textures stay below 2^16 texels from their origin (ground
    // planes of a few hundred metres); the clamp keeps the shifted integer floor below valid.
    const float x = std::clamp(static_cast<float>(u) * L.scale - 0.5f, -60000.0f, 60000.0f);
    const float y = std::clamp(static_cast<float>(v) * L.scale - 0.5f, -60000.0f, 60000.0f);
    const int xi = static_cast<int>(x + 65536.0f) - 65536;  // floor
    const int yi = static_cast<int>(y + 65536.0f) - 65536;
    const float ax = x - static_cast<float>(xi);
    const float ay = y - static_cast<float>(yi);
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
    const float top = static_cast<float>(r0[x0]) + ax * static_cast<float>(r0[x1] - r0[x0]);
    const float bottom = static_cast<float>(r1[x0]) + ax * static_cast<float>(r1[x1] - r1[x0]);
    return top + ay * (bottom - top);
  }

 private:
  struct LevelView {
    const std::uint8_t* data;
    std::ptrdiff_t stride;
    int mask_x, mask_y;  // size - 1 (sizes are powers of two)
    float scale;         // level texels per level-0 texel
  };
  std::vector<cv::Mat> levels_;
  std::vector<LevelView> views_;
  TextureWrap wrap_;
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
