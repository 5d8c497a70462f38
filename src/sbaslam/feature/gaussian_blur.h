#pragma once
// The 7x7, sigma 2 Gaussian blur that ORB-SLAM applies before computing descriptors, bit-exact
// with cv::GaussianBlur(src, dst, {7, 7}, 2, 2, cv::BORDER_REFLECT_101) on 8-bit images (for a
// view, with BORDER_ISOLATED: the border reflects inside the view).
//
// OpenCV computes this blur in fixed point: the kernel is {18, 34, 48, 56, 48, 34, 18} / 256, the
// horizontal pass keeps the exact sums (at most 255 * 256), the vertical pass sums those times the
// kernel exactly and rounds half up: out = (sum + 2^15) >> 16. Doing the same arithmetic here,
// with SSE2 and without OpenCV's per-call kernel construction and thread dispatch, costs about
// half as much on the pyramid's small levels. tests/feature/gaussian_blur_test.cc checks the
// equality with cv::GaussianBlur on random and real images of many sizes.

#include <opencv2/core.hpp>
#include <vector>

namespace sbaslam::feature {

class GaussianBlur7 {
 public:
  // `src` 8-bit, one channel; `dst` is (re)allocated to src's size unless it already has it, and
  // may be a view into a larger buffer. Images smaller than 4 px on a side go to OpenCV.
  void apply(const cv::Mat& src, cv::Mat& dst);

 private:
  std::vector<std::uint8_t> padded_row_;
  std::vector<std::int16_t> horizontal_;  // ring of rows of horizontal sums, minus 2^15
};

}  // namespace sbaslam::feature
