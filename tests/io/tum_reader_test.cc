#include "sbaslam/io/tum_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "helper/expect_error.h"
#include "helper/fixture_copy.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

using test::expect_error_naming;

// There is no TUM image fixture: this builds a small sequence in the TUM layout with real
// fr1_xyz ground truth. rgb at 30 Hz; depth a few ms off, one depth frame missing (rgb 3 then
// has no partner within 0.02 s) and one depth frame in between (not associated).
struct TumSequence {
  std::string dir;
  std::vector<double> rgb_stamps = {10.000, 10.033, 10.066, 10.100, 10.133, 10.166};
  std::vector<double> depth_stamps = {10.004, 10.030, 10.071, 10.084, 10.137, 10.160};
};

TumSequence make_tum_sequence(const TempDir& tmp) {
  TumSequence seq;
  seq.dir = tmp.file("tum");
  fs::create_directories(seq.dir + "/rgb");
  fs::create_directories(seq.dir + "/depth");
  cv::RNG rng(5);
  std::string rgb = "# color images\n# timestamp filename\n", depth = "# depth maps\n";
  for (double t : seq.rgb_stamps) {
    cv::Mat image(48, 64, CV_8UC3);
    rng.fill(image, cv::RNG::UNIFORM, 0, 255);
    const std::string name = fmt::format("rgb/{:.6f}.png", t);
    cv::imwrite(seq.dir + "/" + name, image);
    rgb += fmt::format("{:.6f} {}\n", t, name);
  }
  for (double t : seq.depth_stamps) {
    cv::Mat image(48, 64, CV_16UC1, cv::Scalar(static_cast<int>(std::lround(t * 1000)) % 60000));
    const std::string name = fmt::format("depth/{:.6f}.png", t);
    cv::imwrite(seq.dir + "/" + name, image);
    depth += fmt::format("{:.6f} {}\n", t, name);
  }
  test::write_text_file(seq.dir + "/rgb.txt", rgb);
  test::write_text_file(seq.dir + "/depth.txt", depth);
  fs::copy_file(test::shared_data_dir() + "/trajectories/freiburg1_xyz-groundtruth.txt",
                seq.dir + "/groundtruth.txt");
  return seq;
}

TEST(TumReaderTest, AssociatesRgbAndDepth) {
  TempDir tmp;
  const TumSequence seq = make_tum_sequence(tmp);
  const auto reader = make_dataset_reader("tum", seq.dir);
  EXPECT_EQ(reader->kind(), "tum");
  EXPECT_TRUE(reader->has_depth());
  EXPECT_FALSE(reader->has_right());
  EXPECT_FALSE(reader->calibration().has_value());
  // rgb 10.100 is 0.016 from depth 10.084 but that depth is closer to... nothing else: kept.
  // Expected pairs: (10.000,10.004) (10.033,10.030) (10.066,10.071) (10.100,10.084)
  // (10.133,10.137) (10.166,10.160).
  ASSERT_EQ(reader->size(), 6u);
  const auto& tum = dynamic_cast<const TumReader&>(*reader);
  EXPECT_DOUBLE_EQ(tum.timestamp(3), 10.100);
  EXPECT_DOUBLE_EQ(tum.depth_timestamp(3), 10.084);
  EXPECT_DOUBLE_EQ(tum.depth_timestamp(4), 10.137);

  const FrameData frame = reader->load(2);
  EXPECT_DOUBLE_EQ(frame.timestamp, 10.066);
  EXPECT_EQ(frame.left.type(), CV_8UC1);
  EXPECT_EQ(frame.left.size(), cv::Size(64, 48));
  ASSERT_EQ(frame.depth.type(), CV_16UC1);
  EXPECT_EQ(frame.depth.at<std::uint16_t>(0, 0), 10071);
  EXPECT_EQ(fs::path(frame.left_path).filename(), "10.066000.png");

  const auto gt = reader->ground_truth();
  ASSERT_TRUE(gt.has_value());
  EXPECT_EQ(gt->size(), 3000u);
}

TEST(TumReaderTest, FramesWithoutDepthPartnerAreSkipped) {
  TempDir tmp;
  const TumSequence seq = make_tum_sequence(tmp);
  // Remove depth 10.084: rgb 10.100 is then 0.029 from 10.071 (taken) and 0.037 from 10.137.
  std::string depth = test::read_text_file(seq.dir + "/depth.txt");
  const auto at = depth.find("10.084000");
  depth.erase(at, depth.find('\n', at) + 1 - at);
  test::write_text_file(seq.dir + "/depth.txt", depth);
  const TumReader reader(seq.dir);
  ASSERT_EQ(reader.size(), 5u);
  EXPECT_DOUBLE_EQ(reader.timestamp(3), 10.133);
  // Without depth every rgb frame is used.
  const TumReader mono(seq.dir, DatasetOptions{true, false});
  EXPECT_FALSE(mono.has_depth());
  EXPECT_EQ(mono.size(), 6u);
  EXPECT_TRUE(mono.load(0).depth.empty());
}

TEST(TumReaderTest, AssociationIsGreedyBySmallestGap) {
  // associate.py: the closest pair is taken first, each stamp used once, gap strictly < max.
  const auto m = associate_stamps({0.0, 0.015, 0.05}, {0.014, 0.07}, 0.02);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0], std::make_pair(std::size_t{1}, std::size_t{0}));
  EXPECT_TRUE(associate_stamps({0.0}, {0.02}, 0.02).empty());
  const auto both = associate_stamps({0.0, 0.01}, {0.005, 0.012}, 0.02);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(both[1], std::make_pair(std::size_t{1}, std::size_t{1}));
}

TEST(TumReaderTest, BadListingsAreErrors) {
  TempDir tmp;
  const TumSequence seq = make_tum_sequence(tmp);
  const std::string rgb_txt = seq.dir + "/rgb.txt";
  test::write_text_file(rgb_txt, "10.000000 rgb/10.000000.png\n10.033000 rgb/missing.png\n");
  expect_error_naming([&] { TumReader r(seq.dir); }, rgb_txt + ":2");
  test::write_text_file(rgb_txt, "10.033000 rgb/10.033000.png\n10.000000 rgb/10.000000.png\n");
  expect_error_naming([&] { TumReader r(seq.dir); }, rgb_txt + ":2");
  test::write_text_file(rgb_txt, "# nothing\n");
  expect_error_naming([&] { TumReader r(seq.dir); }, "empty sequence");
  fs::remove(rgb_txt);
  expect_error_naming([&] { TumReader r(seq.dir); }, rgb_txt);
}

TEST(TumReaderTest, CorruptImagesFailOnLoad) {
  TempDir tmp;
  const TumSequence seq = make_tum_sequence(tmp);
  const std::string rgb = seq.dir + "/rgb/10.033000.png";
  test::truncate_file(rgb, 100);
  // An 8-bit image where 16-bit depth is expected.
  const std::string depth = seq.dir + "/depth/10.071000.png";
  cv::imwrite(depth, cv::Mat(48, 64, CV_8UC1, cv::Scalar(3)));
  const TumReader reader(seq.dir);
  EXPECT_NO_THROW(reader.load(0));
  expect_error_naming([&] { reader.load(1); }, rgb);
  expect_error_naming([&] { reader.load(2); }, depth);
}

}  // namespace
}  // namespace sbaslam::io
