// The bench-features CLI: JSON keys and values on the KITTI stereo fixture, errors as one line.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "helper/cli.h"
#include "helper/temp_dir.h"

namespace sbaslam {
namespace {

using test::run_cli;

const std::string kData = std::string(SBASLAM_SHARED_DIR) + "/data";
const std::string kSettings = std::string(SBASLAM_SOURCE_DIR) + "/config/KITTI04-12.yaml";

TEST(BenchFeaturesCommand, WritesTheJsonSummary) {
  test::TempDir dir;
  // The pair's two images under one name in two folders, by symlink (fixtures are not copied).
  std::filesystem::create_directories(dir.path() / "left");
  std::filesystem::create_directories(dir.path() / "right");
  std::filesystem::create_symlink(kData + "/stereo_pairs/kitti06_frame12/left.png",
                                  dir.path() / "left" / "000012.png");
  std::filesystem::create_symlink(kData + "/stereo_pairs/kitti06_frame12/right.png",
                                  dir.path() / "right" / "000012.png");
  const std::string json_path = dir.file("bench.json");
  ASSERT_EQ(run_cli("bench-features --settings " + kSettings + " --left " + dir.file("left") +
                        " --right " + dir.file("right") + " --repeat 1 --json " + json_path,
                    dir.file("out.txt")),
            0);
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GT(j.at("ours_ms").at("median").get<double>(), 0.0);
  EXPECT_GT(j.at("opencv_orb_ms").at("median").get<double>(), 0.0);
  EXPECT_GT(j.at("stereo_pair_ms").at("median").get<double>(), 0.0);
  EXPECT_EQ(j.at("features").get<int>(), 2000);
  EXPECT_EQ(j.at("image_size"), nlohmann::json::array({1226, 370}));
  EXPECT_NEAR(j.at("ours_features_mean").get<double>(), 2000.0, 100.0);
  EXPECT_GT(j.at("stereo_matches_mean").get<double>(), 500.0);
}

TEST(BenchFeaturesCommand, FailsWithOneLineOnBadInput) {
  test::TempDir dir;
  const std::string out = dir.file("out.txt");
  EXPECT_EQ(run_cli("bench-features --settings " + kSettings + " --left " + dir.file("none"), out),
            1);
  std::filesystem::create_directories(dir.path() / "empty");
  EXPECT_EQ(run_cli("bench-features --settings " + kSettings + " --left " + dir.file("empty"), out),
            1);
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  EXPECT_NE(line.find("sba-slam: error:"), std::string::npos) << line;
  EXPECT_NE(line.find("no .png images"), std::string::npos) << line;
}

}  // namespace
}  // namespace sbaslam
