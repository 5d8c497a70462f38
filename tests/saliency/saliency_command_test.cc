// sba-slam saliency predict / make-dataset end to end through the CLI.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "helper/cli.h"
#include "helper/temp_dir.h"

namespace sbaslam {
namespace {

using test::first_line;
using test::run_cli;
namespace fs = std::filesystem;

const std::string kKittiImages =
    std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0";

TEST(SaliencyCommand, PredictWritesMapsOverlaysAndTiming) {
  test::TempDir dir;
  fs::create_directories(dir.path() / "images");
  for (const char* name : {"000000.png", "000001.png", "000002.png"})
    fs::create_symlink(kKittiImages + "/" + name, dir.path() / "images" / name);
  ASSERT_EQ(run_cli("saliency predict --images " + dir.file("images") + " --out " +
                        dir.file("out") + " --overlay --threads 1",
                    dir.file("log.txt")),
            0)
      << first_line(dir.file("log.txt"));
  for (const char* name : {"000000.png", "000001.png", "000002.png"}) {
    const cv::Mat map = cv::imread(dir.file(std::string("out/") + name), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(map.empty()) << name;
    EXPECT_EQ(map.type(), CV_8UC1);
    EXPECT_EQ(map.size(), cv::Size(1226, 370));  // the image's size
    const cv::Mat overlay = cv::imread(dir.file(std::string("out/overlay/") + name));
    EXPECT_EQ(overlay.type(), CV_8UC3);
    EXPECT_EQ(overlay.size(), cv::Size(1226, 370));
  }
  std::ifstream in(dir.file("out/timing.json"));
  const nlohmann::json timing = nlohmann::json::parse(in);
  EXPECT_GT(timing.at("inference_ms").at("median").get<double>(), 0.0);
  EXPECT_EQ(timing.at("threads").get<int>(), 1);
  EXPECT_EQ(timing.at("input_size").size(), 2u);
  EXPECT_EQ(timing.at("frames").get<int>(), 3);
}

TEST(SaliencyCommand, BadInputsAreOneLineErrors) {
  test::TempDir dir;
  const std::string log = dir.file("log.txt");
  EXPECT_EQ(
      run_cli("saliency predict --images " + dir.file("none") + " --out " + dir.file("o"), log), 1);
  EXPECT_NE(first_line(log).find("sba-slam: error: "), std::string::npos) << first_line(log);
  EXPECT_NE(first_line(log).find("not a folder"), std::string::npos) << first_line(log);
  fs::create_directories(dir.path() / "empty");
  EXPECT_EQ(
      run_cli("saliency predict --images " + dir.file("empty") + " --out " + dir.file("o"), log),
      1);
  EXPECT_NE(first_line(log).find("no .png or .jpg images"), std::string::npos) << first_line(log);
  EXPECT_EQ(run_cli("saliency predict --images " + kKittiImages + " --out " + dir.file("o") +
                        " --model " + dir.file("missing.onnx"),
                    log),
            1);
  EXPECT_NE(first_line(log).find("missing.onnx: saliency model file does not exist"),
            std::string::npos)
      << first_line(log);
  EXPECT_EQ(
      run_cli("saliency make-dataset --sim " + dir.file("empty") + " --out " + dir.file("o"), log),
      1);
  EXPECT_NE(first_line(log).find("no simulated images with labels"), std::string::npos)
      << first_line(log);
}

TEST(SaliencyCommand, MakeDatasetFromImageAndLabelFolders) {
  test::TempDir dir;
  fs::create_directories(dir.path() / "labels");
  fs::create_directories(dir.path() / "images");
  fs::create_symlink(kKittiImages + "/000000.png", dir.path() / "images" / "000000.png");
  cv::Mat labels(370, 1226, CV_8U, cv::Scalar(11));  // building...
  labels(cv::Rect(0, 0, 1226, 100)).setTo(23);       // ...under a band of sky
  cv::imwrite(dir.file("labels/000000.png"), labels);
  ASSERT_EQ(run_cli("saliency make-dataset --images " + dir.file("images") + " --labels " +
                        dir.file("labels") + " --out " + dir.file("ds"),
                    dir.file("log.txt")),
            0)
      << first_line(dir.file("log.txt"));
  const cv::Mat fixations = cv::imread(dir.file("ds/fixations/000000.png"), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(fixations.size(), cv::Size(1226, 370));
  EXPECT_EQ(cv::countNonZero(fixations(cv::Rect(0, 0, 1226, 100))), 0);
  EXPECT_GT(cv::countNonZero(fixations(cv::Rect(0, 110, 1226, 260))), 200);
}

}  // namespace
}  // namespace sbaslam
