#include "sbaslam/feature/band_sad.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

namespace sbaslam::feature {
namespace {

// The definition: the rounded mean difference, then the sum of |left - right - offset|.
int reference_sad(const WindowPair& w, bool zero_mean) {
  int left_sum = 0, right_sum = 0;
  for (int r = 0; r < w.size; ++r)
    for (int c = 0; c < w.size; ++c) {
      left_sum += w.left[r * w.left_step + c];
      right_sum += w.right[r * w.right_step + c];
    }
  const int offset = zero_mean
                         ? static_cast<int>(std::lround(static_cast<double>(left_sum - right_sum) /
                                                        static_cast<double>(w.size * w.size)))
                         : 0;
  int sad = 0;
  for (int r = 0; r < w.size; ++r)
    for (int c = 0; c < w.size; ++c)
      sad += std::abs(w.left[r * w.left_step + c] - w.right[r * w.right_step + c] - offset);
  return sad;
}

// Random windows over random grey ranges: narrow ranges near 0 or 255 push the 8-bit sums into
// saturation, so every path (right raised, left lowered, left raised, right lowered, 16-bit) is
// taken many times.
TEST(BandSad, EveryPathEqualsTheDefinition) {
  std::mt19937 rng(3);
  constexpr int kLeftStep = 40, kRightStep = 120;
  std::vector<std::uint8_t> left(20 * kLeftStep), right(20 * kRightStep);
  auto fill = [&](std::vector<std::uint8_t>& pixels) {
    int lo = static_cast<int>(rng() % 256), hi = static_cast<int>(rng() % 256);
    if (lo > hi) std::swap(lo, hi);
    for (std::uint8_t& p : pixels) p = static_cast<std::uint8_t>(lo + rng() % (hi - lo + 1));
  };
  int checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    fill(left);
    fill(right);
    const int size = std::min(15, 1 + 2 * static_cast<int>(rng() % 8));
    const int positions = 2 * (1 + static_cast<int>(rng() % kMaxSadSearch)) + 1;
    const WindowPair first{left.data() + 2, kLeftStep, right.data() + 3, kRightStep, size};
    for (bool zero_mean : {true, false}) {
      const BandSad band(first, positions, zero_mean);
      for (int p = 0; p < positions; ++p) {
        WindowPair w = first;
        w.right += p;
        ASSERT_EQ(band.at(p), reference_sad(w, zero_mean))
            << "size " << size << ", position " << p << " of " << positions << ", zero_mean "
            << zero_mean;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100000);
}

}  // namespace
}  // namespace sbaslam::feature
