#include "sbaslam/feature/gaussian_blur.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "helper/images.h"
#include "sbaslam/core/error.h"

namespace sbaslam::feature {
namespace {

// Isolated: OpenCV would otherwise read a view's border from the pixels around it, where ours
// reflects inside the view. (No descriptor reads the blur within 5 px of a level's border, so the
// border rule never shows in the features.)
cv::Mat opencv_blur(const cv::Mat& src) {
  cv::Mat dst;
  cv::GaussianBlur(src, dst, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
  return dst;
}

// Bit-exact, so that descriptors do not change with the implementation: random images (every
// grey level, sharp steps) of sizes around the SIMD widths, 16 and 8, and the border cases.
TEST(GaussianBlur7, EqualsOpenCvOnRandomImages) {
  cv::RNG rng(4);
  GaussianBlur7 blur;
  for (int rows : {1, 3, 4, 5, 7, 8, 13, 31}) {
    for (int cols : {1, 2, 4, 5, 7, 8, 9, 15, 16, 17, 23, 24, 25, 33, 64, 100}) {
      cv::Mat src(rows, cols, CV_8U);
      rng.fill(src, cv::RNG::UNIFORM, 0, 256);
      cv::Mat ours;
      blur.apply(src, ours);
      ASSERT_EQ(ours.size(), src.size());
      EXPECT_EQ(cv::norm(ours, opencv_blur(src), cv::NORM_INF), 0.0) << rows << "x" << cols;
    }
  }
  // Saturated extremes: the sums reach their largest values.
  cv::Mat white(20, 40, CV_8U, cv::Scalar(255)), ours;
  white(cv::Rect(5, 5, 10, 10)).setTo(0);
  blur.apply(white, ours);
  EXPECT_EQ(cv::norm(ours, opencv_blur(white), cv::NORM_INF), 0.0);
}

TEST(GaussianBlur7, EqualsOpenCvOnRealImagesAndViews) {
  const std::string data = std::string(SBASLAM_SHARED_DIR) + "/data";
  GaussianBlur7 blur;
  for (const std::string& path :
       {data + "/stereo_pairs/kitti06_frame12/left.png",
        data + "/euroc_v101_micro/mav0/cam0/data/1403715273262142976.png"}) {
    const cv::Mat image = test::read_gray(path);
    cv::Mat ours;
    blur.apply(image, ours);
    EXPECT_EQ(cv::norm(ours, opencv_blur(image), cv::NORM_INF), 0.0) << path;
    // A view as input and a view of a larger buffer as output (as the extractor uses it).
    const cv::Mat view = image(cv::Rect(3, 5, image.cols / 2 + 1, image.rows / 2 + 3));
    cv::Mat buffer(image.size(), CV_8U, cv::Scalar(7));
    cv::Mat out = buffer(cv::Rect(0, 0, view.cols, view.rows));
    const std::uint8_t* before = out.data;
    blur.apply(view, out);
    EXPECT_EQ(out.data, before) << "the output view was reallocated";
    EXPECT_EQ(cv::norm(out, opencv_blur(view), cv::NORM_INF), 0.0) << path;
  }
  cv::Mat colour(10, 10, CV_8UC3), out;
  EXPECT_THROW(blur.apply(colour, out), Error);
}

}  // namespace
}  // namespace sbaslam::feature
