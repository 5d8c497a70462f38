#pragma once
// The window comparison of the stereo matcher: the SAD of a left window against the right windows
// at consecutive columns of a band of the right image, raw (ORB-SLAM3) or zero-mean, where each
// right window is compared after removing the rounded difference of the two windows' means.
//
// The zero-mean sum runs in 8-bit lanes with one window moved by the offset with saturation,
// which is exact whenever nothing saturates; the windows' extremes tell when that could happen,
// and a 16-bit sum answers then. tests/feature/band_sad_test.cc checks every path against the
// definition.

#include <cstddef>
#include <cstdint>

namespace sbaslam::feature {

// Windows are at most 16 pixels wide (window_half <= 7) and read as 16-byte rows, so a row must
// follow the last one of a window or band: the caller guarantees it (keypoints sit
// kEdgeThreshold px inside a level, and the matcher checks that a row exists below).
inline constexpr int kMaxSadWindow = 16;
inline constexpr int kMaxSadSearch = 30;  // positions on each side of the centre

// Two windows of size x size pixels, given by their top-left pixels and row steps.
struct WindowPair {
  const std::uint8_t* left;
  std::size_t left_step;
  const std::uint8_t* right;
  std::size_t right_step;
  int size;
};

class BandSad {
 public:
  // `first` pairs the left window with the right window at the band's first position; position p
  // moves the right window p pixels to the right. positions <= 2 * kMaxSadSearch + 1. With
  // zero_mean, the offsets of all positions come from the band's column sums, one pass over it.
  BandSad(const WindowPair& first, int positions, bool zero_mean);

  // Sum over the windows at `position` of |left - right - offset| (offset 0 without zero_mean).
  int at(int position) const;

 private:
  void prepare_offsets(int positions);
  // Fills the band's column sums and the extremes; returns the left window's sum.
  int sums_and_extremes(int columns, std::int16_t* column_sum);

  WindowPair first_;
  int offsets_[2 * kMaxSadSearch + 1] = {};
  // Extremes of the left window and of the band's right pixels (0 and 255 without zero_mean,
  // where every offset is 0).
  int left_max_ = 0, band_max_ = 0, left_min_ = 255, band_min_ = 255;
};

}  // namespace sbaslam::feature
