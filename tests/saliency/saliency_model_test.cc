// The shipped ONNX model through OpenCV dnn gives PyTorch's output; sources and their errors.

#include "sbaslam/saliency/saliency_model.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"
#include "sbaslam/saliency/saliency_source.h"

namespace sbaslam::saliency {
namespace {

const std::string kModels = std::string(SBASLAM_SOURCE_DIR) + "/models";
const std::string kKittiImage =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0/000000.png";

// python/train_saliency.py's check_input(): u8 = (3x + 5y + 7((x*y) mod 17)) mod 256, / 255.
cv::Mat check_input(cv::Size size) {
  cv::Mat input(size, CV_32F);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      input.at<float>(y, x) =
          static_cast<float>((3 * x + 5 * y + 7 * ((x * y) % 17)) % 256) / 255.0f;
  return input;
}

TEST(SaliencyModel, OpenCvDnnEqualsPyTorchOnTheCheckInput) {
  SaliencyModel model(kModels + "/saliency_model.onnx");
  const cv::Size size = model.input_size();
  std::ifstream card_file(kModels + "/saliency_model.json");
  const nlohmann::json card = nlohmann::json::parse(card_file);
  std::ifstream in(kModels + "/" + card.at("check_logits").get<std::string>(), std::ios::binary);
  std::vector<float> expected(static_cast<std::size_t>(size.area()));
  in.read(reinterpret_cast<char*>(expected.data()),
          static_cast<std::streamsize>(expected.size() * sizeof(float)));
  ASSERT_TRUE(in) << "check file shorter than the model's output";
  const cv::Mat logits = model.logits(check_input(size));
  ASSERT_EQ(logits.size(), size);
  double worst = 0.0;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      worst = std::max(worst, std::abs(double(logits.at<float>(y, x)) -
                                       expected[static_cast<std::size_t>(y * size.width + x)]));
  EXPECT_LT(worst, 1e-4);
}

TEST(SaliencyModel, PredictsAnEightBitMapWithItsPeakAt255) {
  SaliencyModel model(shipped_model_path());
  const cv::Mat image = cv::imread(kKittiImage, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  const cv::Mat map = model.predict(image);
  EXPECT_EQ(map.type(), CV_8UC1);
  EXPECT_EQ(map.size(), model.input_size());
  double lo = 0, hi = 0;
  cv::minMaxLoc(map, &lo, &hi);
  EXPECT_EQ(hi, 255.0);
  EXPECT_LT(lo, 128.0);  // not flat
  EXPECT_THROW(model.predict(cv::Mat(10, 10, CV_32F)), Error);
}

TEST(SaliencyModel, MissingOrCorruptModelIsAOneLineError) {
  test::TempDir dir;
  EXPECT_NE(
      test::error_message([&] { SaliencyModel m(dir.file("none.onnx")); }).find("does not exist"),
      std::string::npos);
  { std::ofstream(dir.file("bad.onnx")) << "not a protobuf"; }
  EXPECT_NE(test::error_message([&] {
              SaliencyModel m(dir.file("bad.onnx"));
            }).find("model card missing"),
            std::string::npos);
  { std::ofstream(dir.file("bad.json")) << R"({"input_size": [320, 96]})"; }
  const std::string corrupt = test::error_message([&] { SaliencyModel m(dir.file("bad.onnx")); });
  EXPECT_NE(corrupt.find("not a readable ONNX model"), std::string::npos) << corrupt;
}

TEST(SaliencySource, NoneModelAndFolder) {
  SaliencySettings settings;
  const cv::Mat image(40, 60, CV_8U, cv::Scalar(90));
  EXPECT_TRUE(make_saliency_source("none", settings)->predict(image, 0.0, "x.png").empty());
  EXPECT_FALSE(make_saliency_source("model", settings)->predict(image, 0.0, "x.png").empty());
  settings.model_path = "/nonexistent/model.onnx";
  EXPECT_THROW(make_saliency_source("model", settings), Error);
  EXPECT_NE(test::error_message([&] {
              make_saliency_source("/nonexistent/folder", settings);
            }).find("must be 'none', 'model' or a folder"),
            std::string::npos);
}

TEST(SaliencySource, PrecomputedFolderReadsMapsByImageName) {
  test::TempDir dir;
  const cv::Mat a(30, 40, CV_8U, cv::Scalar(17)), b(30, 40, CV_8U, cv::Scalar(99));
  cv::imwrite(dir.file("000001.png"), a);
  cv::imwrite(dir.file("000002.png"), b);
  auto source = make_saliency_source(dir.path().string(), SaliencySettings{});
  const cv::Mat image(30, 40, CV_8U, cv::Scalar(0));
  EXPECT_EQ(source->predict(image, 0.1, "/data/seq/image_0/000002.png").at<std::uint8_t>(5, 5), 99);
  // A .jpg frame finds the map of the same stem.
  EXPECT_EQ(source->predict(image, 0.0, "/data/frames/000001.jpg").at<std::uint8_t>(5, 5), 17);
  const std::string missing =
      test::error_message([&] { source->predict(image, 0.2, "/data/000003.png"); });
  EXPECT_NE(missing.find("000003.png: no saliency map for image /data/000003.png"),
            std::string::npos)
      << missing;
}

}  // namespace
}  // namespace sbaslam::saliency
