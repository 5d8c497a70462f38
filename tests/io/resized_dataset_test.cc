#include "sbaslam/io/resized_dataset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "helper/expect_error.h"

namespace sbaslam::io {
namespace {

// A 1-frame dataset whose left image holds a Gaussian dot centred at a sub-pixel position.
class DotDataset : public DatasetReader {
 public:
  DotDataset(cv::Size size, Vec2 dot) : size_(size), dot_(dot) {}
  std::string kind() const override { return "kitti"; }
  std::size_t size() const override { return 1; }
  double timestamp(std::size_t) const override { return 0.0; }
  bool has_right() const override { return true; }
  bool has_depth() const override { return true; }
  FrameData load(std::size_t) const override {
    FrameData frame;
    frame.left_path = "dot.png";
    frame.left = cv::Mat(size_, CV_8UC1);
    for (int y = 0; y < size_.height; ++y)
      for (int x = 0; x < size_.width; ++x) {
        const double r2 = (Vec2(x, y) - dot_).squaredNorm();
        frame.left.at<std::uint8_t>(y, x) =
            cv::saturate_cast<std::uint8_t>(250.0 * std::exp(-r2 / 18.0));
      }
    frame.right = frame.left.clone();
    frame.depth = cv::Mat(size_, CV_16UC1);
    for (int y = 0; y < size_.height; ++y)
      for (int x = 0; x < size_.width; ++x) frame.depth.at<std::uint16_t>(y, x) = 1000 + x;
    return frame;
  }
  std::optional<DatasetCalibration> calibration() const override {
    DatasetCalibration calib;
    calib.camera.intrinsics = {400.0, 380.0, 300.5, 120.25};
    calib.camera.width = size_.width;
    calib.camera.height = size_.height;
    calib.stereo = StereoRig(calib.camera.intrinsics, 0.5);
    return calib;
  }
  Vec2 file_pixel(const Vec2& pixel) const override { return pixel + Vec2(1000.0, 0.0); }

 private:
  cv::Size size_;
  Vec2 dot_;
};

Vec2 centroid(const cv::Mat& image) {
  const cv::Moments m = cv::moments(image);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

// The dot lands where the scaled camera projects the ray that the original camera saw it along.
TEST(ResizedDataset, TheScaledCameraProjectsWhereCvResizePutsThePixels) {
  const cv::Size from(600, 240);
  const Vec2 dot(211.3, 97.6);
  for (const cv::Size to : {cv::Size(300, 120), cv::Size(450, 180), cv::Size(900, 360)}) {
    SCOPED_TRACE(to.width);
    const ImageScaling scaling = image_scaling({to.width, to.height}, from, "s.yaml");
    const ResizedDataset resized(std::make_unique<DotDataset>(from, dot), scaling);
    const FrameData frame = resized.load(0);
    ASSERT_EQ(frame.left.size(), to);
    ASSERT_EQ(frame.right.size(), to);
    ASSERT_EQ(frame.depth.size(), to);
    const Vec2 seen = centroid(frame.left);
    const PinholeIntrinsics k = DotDataset(from, dot).calibration()->camera.intrinsics;
    const PinholeIntrinsics ks = scaling.scaled(k);
    const Vec2 ray((dot.x() - k.cx) / k.fx, (dot.y() - k.cy) / k.fy);
    const Vec2 projected(ks.fx * ray.x() + ks.cx, ks.fy * ray.y() + ks.cy);
    EXPECT_LT((seen - projected).norm(), 0.02)
        << seen.transpose() << " / " << projected.transpose();
    EXPECT_LT((scaling.to_original(seen) - dot).norm(), 0.04);
    // The file pixel goes through the inner dataset's own mapping.
    EXPECT_LT((resized.file_pixel(projected) - (dot + Vec2(1000.0, 0.0))).norm(), 1e-9);
  }
}

TEST(ResizedDataset, DepthIsResampledByTheNearestPixelAndTheRigIsScaled) {
  const cv::Size from(600, 240);
  const ImageScaling scaling = image_scaling({300, 0}, from, "s.yaml");  // width only
  EXPECT_EQ(scaling.to, cv::Size(300, 240));
  const ResizedDataset resized(std::make_unique<DotDataset>(from, Vec2(50, 50)), scaling);
  const cv::Mat depth = resized.load(0).depth;
  for (int x = 0; x < depth.cols; ++x) {
    const int value = depth.at<std::uint16_t>(7, x);
    EXPECT_TRUE(value == 1000 + 2 * x || value == 1001 + 2 * x) << x;  // a value that was there
  }
  const DatasetCalibration calib = *resized.calibration();
  EXPECT_EQ(calib.camera.width, 300);
  EXPECT_EQ(calib.camera.height, 240);
  EXPECT_DOUBLE_EQ(calib.camera.intrinsics.fx, 200.0);
  EXPECT_DOUBLE_EQ(calib.camera.intrinsics.fy, 380.0);
  EXPECT_DOUBLE_EQ(calib.camera.intrinsics.cx, (300.5 + 0.5) * 0.5 - 0.5);
  EXPECT_DOUBLE_EQ(calib.camera.intrinsics.cy, 120.25);
  ASSERT_TRUE(calib.stereo.has_value());
  EXPECT_DOUBLE_EQ(calib.stereo->baseline, 0.5);
  EXPECT_DOUBLE_EQ(calib.stereo->bf, 100.0);  // disparities halve with the width
}

TEST(ResizedDataset, RefusesAnImageOfAnotherSizeAndAnExtremeOrUnknownScale) {
  const ImageScaling scaling = image_scaling({320, 120}, cv::Size(640, 240), "s.yaml");
  const ResizedDataset resized(std::make_unique<DotDataset>(cv::Size(600, 240), Vec2(5, 5)),
                               scaling);
  test::expect_error_naming([&] { resized.load(0); },
                            "dot.png: the image is 600x240, but the settings describe 640x240");
  test::expect_error_naming(
      [&] {
        image_scaling({64, 0}, cv::Size(640, 240), "s.yaml");
      },
      "s.yaml: Camera.newWidth/newHeight 64x240 resize 640x240 images");
  test::expect_error_naming(
      [&] {
        image_scaling({64, 0}, cv::Size(0, 0), "s.yaml");
      },
      "s.yaml: Camera.newWidth/newHeight given, but the images' own size");
}

}  // namespace
}  // namespace sbaslam::io
