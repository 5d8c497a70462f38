#include "sbaslam/io/kitti_reader.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "helper/expect_error.h"
#include "helper/fixture_copy.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

using test::expect_error_naming;

TEST(KittiReaderTest, ReadsTheFixture) {
  const KittiReader reader(test::kitti_fixture_sequence_dir());
  EXPECT_EQ(reader.kind(), "kitti");
  ASSERT_EQ(reader.size(), 51u);
  EXPECT_DOUBLE_EQ(reader.timestamp(0), 0.0);
  EXPECT_DOUBLE_EQ(reader.timestamp(1), 1.044989e-01);
  EXPECT_DOUBLE_EQ(reader.timestamp(50), 5.195994);
  EXPECT_FALSE(reader.has_right());
  EXPECT_FALSE(reader.has_depth());
  EXPECT_NEAR(reader.baseline(), 379.8145 / 707.0912, 1e-12);

  const auto calib = reader.calibration();
  ASSERT_TRUE(calib.has_value());
  EXPECT_DOUBLE_EQ(calib->camera.intrinsics.fx, 707.0912);
  EXPECT_DOUBLE_EQ(calib->camera.intrinsics.cx, 601.8873);
  EXPECT_DOUBLE_EQ(calib->camera.intrinsics.cy, 183.1104);
  EXPECT_EQ(calib->camera.width, 1226);
  EXPECT_EQ(calib->camera.height, 370);
  EXPECT_FALSE(calib->stereo.has_value());

  const FrameData frame = reader.load(50);
  EXPECT_EQ(frame.index, 50u);
  EXPECT_DOUBLE_EQ(frame.timestamp, 5.195994);
  EXPECT_EQ(frame.left.type(), CV_8UC1);
  EXPECT_EQ(frame.left.size(), cv::Size(1226, 370));
  EXPECT_TRUE(frame.right.empty());
  EXPECT_EQ(fs::path(frame.left_path).filename(), "000050.png");

  const auto gt = reader.ground_truth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 51u);
  EXPECT_DOUBLE_EQ(gt->stamps[50], 5.195994);
  EXPECT_LT(gt->poses[0].translation().norm(), 1e-12);
  EXPECT_NEAR(gt->poses[50].translation().z(), 5.983857e+01, 1e-9);
}

TEST(KittiReaderTest, FactoryAcceptsTrailingSlash) {
  const auto reader = make_dataset_reader("kitti", test::kitti_fixture_sequence_dir() + "/");
  EXPECT_EQ(reader->size(), 51u);
  EXPECT_TRUE(reader->ground_truth().has_value());
}

TEST(KittiReaderTest, StereoCopyGivesRightImagesAndBaseline) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  fs::copy(seq + "/image_0", seq + "/image_1");
  const KittiReader reader(seq);
  EXPECT_TRUE(reader.has_right());
  const auto calib = reader.calibration();
  ASSERT_TRUE(calib->stereo.has_value());
  EXPECT_NEAR(calib->stereo->baseline, 0.537150, 1e-6);
  EXPECT_NEAR(calib->stereo->bf, 379.8145, 1e-9);
  const FrameData frame = reader.load(2);
  EXPECT_EQ(frame.right.size(), frame.left.size());
  // Monocular use skips the right images.
  EXPECT_FALSE(KittiReader(seq, DatasetOptions{false, true}).has_right());
}

TEST(KittiReaderTest, RightImageCountMismatchIsAnError) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  fs::copy(seq + "/image_0", seq + "/image_1");
  fs::remove(seq + "/image_1/000004.png");
  expect_error_naming([&] { KittiReader reader(seq); }, "image_1");
}

TEST(KittiReaderTest, TimesCountMismatchIsAnError) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  const std::string times = seq + "/times.txt";
  test::write_text_file(times, "0.0\n0.1\n0.2\n0.3\n");  // shorter
  expect_error_naming([&] { KittiReader reader(seq); }, times);
  test::write_text_file(times, "0.0\n0.1\n0.2\n0.3\n0.4\n0.5\n");  // longer
  expect_error_naming([&] { KittiReader reader(seq); }, times);
}

TEST(KittiReaderTest, BadTimesAreErrors) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  const std::string times = seq + "/times.txt";
  test::write_text_file(times, "0.0\n0.1\n0.3\n0.2\n0.4\n");
  expect_error_naming([&] { KittiReader reader(seq); }, times);
  test::write_text_file(times, "0.0\n0.1\n0.1\n0.2\n0.4\n");
  expect_error_naming([&] { KittiReader reader(seq); }, "duplicate");
  test::write_text_file(times, "0.0\n0.1\nnan\n0.2\n0.4\n");
  expect_error_naming([&] { KittiReader reader(seq); }, times + ":3");
}

TEST(KittiReaderTest, MissingCalibrationOrImagesAreErrors) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 3);
  fs::remove(seq + "/calib.txt");
  expect_error_naming([&] { KittiReader reader(seq); }, seq + "/calib.txt");
  test::write_text_file(seq + "/calib.txt", "P1: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  expect_error_naming([&] { KittiReader reader(seq); }, "P0");
  test::write_text_file(seq + "/calib.txt", "P0: 1 0 0 0 0 1 0\n");
  expect_error_naming([&] { KittiReader reader(seq); }, seq + "/calib.txt:1");

  TempDir empty;
  fs::create_directories(empty.path() / "image_0");
  expect_error_naming([&] { KittiReader reader(empty.path().string()); }, "empty sequence");
  expect_error_naming([&] { KittiReader reader(tmp.file("nowhere")); }, "image_0");
}

TEST(KittiReaderTest, TruncatedImageFailsOnLoadOnly) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  const std::string broken = seq + "/image_0/000003.png";
  test::truncate_file(broken, 2000);
  const KittiReader reader(seq);  // construction decodes nothing
  EXPECT_NO_THROW(reader.load(2));
  expect_error_naming([&] { reader.load(3); }, broken);
}

TEST(KittiReaderTest, GroundTruthRowCountMustMatch) {
  TempDir tmp;
  const std::string seq = test::copy_kitti_subset(tmp.path().string(), 5);
  const KittiReader reader(seq);
  ASSERT_TRUE(reader.ground_truth().has_value());
  EXPECT_EQ(reader.ground_truth()->size(), 5u);
  test::write_text_file(reader.poses_path(), "1 0 0 0 0 1 0 0 0 0 1 0\n");
  expect_error_naming([&] { reader.ground_truth(); }, reader.poses_path());
  fs::remove(reader.poses_path());
  EXPECT_FALSE(reader.ground_truth().has_value());
}

}  // namespace
}  // namespace sbaslam::io
