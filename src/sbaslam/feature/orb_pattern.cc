#include "sbaslam/feature/orb_pattern.h"

#include <cmath>
#include <random>

namespace sbaslam::feature {
namespace {

// mt19937's output sequence is fixed by the standard, unlike std::normal_distribution's, so the
// Gaussian is drawn by hand (Box-Muller) to give the same pattern with every standard library.
class PortableGaussian {
 public:
  explicit PortableGaussian(std::uint32_t seed) : engine_(seed) {}
  double next() {
    const double u1 = (static_cast<double>(engine_()) + 0.5) / 4294967296.0;
    const double u2 = (static_cast<double>(engine_()) + 0.5) / 4294967296.0;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937 engine_;
};

PatternPoint draw_point_in_disc(PortableGaussian& gaussian) {
  const double sigma = kPatchSize / 5.0;
  for (;;) {
    const int x = static_cast<int>(std::lround(sigma * gaussian.next()));
    const int y = static_cast<int>(std::lround(sigma * gaussian.next()));
    if (x * x + y * y <= kPatternRadius * kPatternRadius)
      return {static_cast<float>(x), static_cast<float>(y)};
  }
}

std::array<PatternPoint, 2 * kDescriptorBits> make_pattern() {
  PortableGaussian gaussian(0x5BA51A11u);
  std::array<PatternPoint, 2 * kDescriptorBits> pattern{};
  for (int i = 0; i < kDescriptorBits; ++i) {
    PatternPoint a{}, b{};
    do {  // a test comparing a pixel with itself carries no information
      a = draw_point_in_disc(gaussian);
      b = draw_point_in_disc(gaussian);
    } while (a.x == b.x && a.y == b.y);
    pattern[2 * i] = a;
    pattern[2 * i + 1] = b;
  }
  return pattern;
}

std::array<int, kHalfPatch + 1> make_umax() {
  std::array<int, kHalfPatch + 1> umax{};
  const int radius2 = kHalfPatch * kHalfPatch + kHalfPatch;
  for (int v = 0; v <= kHalfPatch; ++v) {
    int u = 0;
    while ((u + 1) * (u + 1) + v * v <= radius2) ++u;
    umax[v] = u;
  }
  return umax;
}

}  // namespace

const std::array<PatternPoint, 2 * kDescriptorBits>& brief_pattern() {
  static const auto pattern = make_pattern();
  return pattern;
}

const std::array<int, kHalfPatch + 1>& orientation_patch_umax() {
  static const auto umax = make_umax();
  return umax;
}

}  // namespace sbaslam::feature
