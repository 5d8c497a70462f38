// Saliency.depth "model": a user's ONNX depth network through OpenCV dnn. The network here is
// tests/data/depth_model_test.onnx (python/make_test_depth_model.py), a fixed function with a
// known answer: depth = 1 + 9 * (mean of the RGB channels in [0, 1]) on a 64x32 input.

#include "sbaslam/saliency/depth_model.h"

#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgproc.hpp>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"
#include "sbaslam/saliency/depth_correction.h"

namespace sbaslam::saliency {
namespace {

const std::string kTestModel =
    std::string(SBASLAM_SOURCE_DIR) + "/tests/data/depth_model_test.onnx";

DepthModelSettings test_model(bool inverse) {
  DepthModelSettings s;
  s.path = kTestModel;
  s.width = 64;
  s.height = 32;
  s.channels = 3;
  s.inverse = inverse;
  return s;
}

// A 320x160 image whose grey level grows to the right and downwards.
cv::Mat gradient_image() {
  cv::Mat image(160, 320, CV_8U);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((x * 200) / 320 + y / 4);
  return image;
}

TEST(DepthModel, OutputIsTheNetworksDepthOrItsInverse) {
  const cv::Mat image = gradient_image();
  cv::Mat small;
  cv::resize(image, small, cv::Size(64, 32), 0, 0, cv::INTER_AREA);
  DepthModel direct(test_model(false)), inverse(test_model(true));
  const cv::Mat d = direct.predict(image), d_inv = inverse.predict(image);
  ASSERT_EQ(d.size(), cv::Size(64, 32));
  ASSERT_EQ(d.type(), CV_32F);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const double expected = 1.0 + 9.0 * small.at<std::uint8_t>(y, x) / 255.0;
      EXPECT_NEAR(d.at<float>(y, x), expected, 1e-4) << x << "," << y;
      EXPECT_NEAR(d_inv.at<float>(y, x), 1.0 / expected, 1e-5) << x << "," << y;
    }
}

// Algorithm 1 with D from the network: on a uniform S_init the result is 255 * D_min / D.
TEST(DepthModel, DrivesTheDepthCorrection) {
  const cv::Mat image = gradient_image();
  DepthModel model(test_model(false));
  const cv::Mat depth = model.predict(image);
  const cv::Mat s_init(96, 320, CV_8U, cv::Scalar(255));
  const cv::Mat s = depth_corrected_saliency(s_init, depth, 1.0, 0.0);
  double d_min = 0.0;
  cv::minMaxLoc(depth, &d_min);
  cv::Mat d_resized;
  cv::resize(depth, d_resized, s_init.size(), 0, 0, cv::INTER_NEAREST);
  for (int y = 0; y < s.rows; y += 7)
    for (int x = 0; x < s.cols; x += 11)
      EXPECT_NEAR(s.at<std::uint8_t>(y, x), 255.0 * d_min / d_resized.at<float>(y, x), 0.51);
}

TEST(DepthModel, BadFilesGiveOneLineErrorsNamingThem) {
  DepthModelSettings missing = test_model(true);
  missing.path = "/nonexistent/depth.onnx";
  const std::string m1 = test::error_message([&] { DepthModel model(missing); });
  EXPECT_NE(m1.find("/nonexistent/depth.onnx"), std::string::npos) << m1;
  EXPECT_NE(m1.find("does not exist"), std::string::npos) << m1;

  test::TempDir dir;
  const std::string junk = dir.file("junk.onnx");
  std::ofstream(junk) << "not a network";
  DepthModelSettings corrupt = test_model(true);
  corrupt.path = junk;
  const std::string m2 = test::error_message([&] { DepthModel model(corrupt); });
  EXPECT_NE(m2.find(junk), std::string::npos) << m2;
  EXPECT_NE(m2.find("not a readable ONNX model"), std::string::npos) << m2;
  EXPECT_EQ(m2.find('\n'), std::string::npos) << m2;
}

}  // namespace
}  // namespace sbaslam::saliency
