#include "sbaslam/io/euroc_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "helper/expect_error.h"
#include "helper/fixture_copy.h"
#include "helper/orbslam2_stereo.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/settings.h"

namespace sbaslam::io {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

using test::expect_error_naming;

TEST(EurocReaderTest, ReadsTheStereoFixture) {
  const EurocReader reader(test::euroc_fixture_dir());
  EXPECT_EQ(reader.kind(), "euroc");
  // cam0 has 95 frames, cam1 99 (it runs longer); every cam0 frame has a partner.
  ASSERT_EQ(reader.size(), 95u);
  EXPECT_TRUE(reader.has_right());
  EXPECT_EQ(reader.timestamp_ns(0), 1403715273262142976);
  EXPECT_EQ(reader.timestamp_ns(94), 1403715277962142976);
  EXPECT_NEAR(reader.timestamp(0), 1403715273.262142976, 1e-6);
  EXPECT_NEAR(reader.timestamp(94) - reader.timestamp(0), 4.7, 1e-6);
  EXPECT_FALSE(reader.ground_truth().has_value());  // the fixture has no ASL ground-truth csv

  const auto calib = reader.calibration();
  ASSERT_TRUE(calib.has_value());
  ASSERT_TRUE(calib->stereo.has_value());
  EXPECT_NEAR(calib->stereo->baseline, 0.110078, 1e-6);
  EXPECT_TRUE(calib->camera.distortion.is_zero());
  EXPECT_DOUBLE_EQ(calib->camera.intrinsics.fx, calib->stereo->intrinsics.fx);
  EXPECT_EQ(calib->camera.width, 752);
  EXPECT_GT(calib->T_cam0_image.so3().angle(), 1e-4);
  EXPECT_TRUE(calib->T_body_cam0.matrix().isApprox(reader.cam0().T_BS.matrix()));
  EXPECT_NEAR(calib->T_body_cam0.translation().x(), -0.0216401454975, 1e-12);

  const FrameData frame = reader.load(94);
  EXPECT_EQ(frame.index, 94u);
  EXPECT_EQ(frame.left.type(), CV_8UC1);
  EXPECT_EQ(frame.right.type(), CV_8UC1);
  EXPECT_EQ(frame.left.size(), cv::Size(752, 480));
  EXPECT_EQ(frame.right.size(), cv::Size(752, 480));
  EXPECT_EQ(fs::path(frame.left_path).filename(), "1403715277962142976.png");
  // Rectified: not the raw image.
  const cv::Mat raw = cv::imread(frame.left_path, cv::IMREAD_GRAYSCALE);
  EXPECT_GT(cv::norm(raw, frame.left, cv::NORM_L1), 0.0);
}

TEST(EurocReaderTest, MonocularReturnsRawCam0) {
  const auto reader =
      make_dataset_reader("euroc", test::euroc_fixture_dir(), DatasetOptions{false, true});
  EXPECT_EQ(reader->size(), 95u);
  EXPECT_FALSE(reader->has_right());
  const auto calib = reader->calibration();
  ASSERT_TRUE(calib.has_value());
  EXPECT_FALSE(calib->stereo.has_value());
  EXPECT_DOUBLE_EQ(calib->camera.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(calib->camera.distortion.k1, -0.28340811);
  EXPECT_TRUE(calib->T_cam0_image.matrix().isApprox(Mat4::Identity()));
  const FrameData frame = reader->load(3);
  EXPECT_TRUE(frame.right.empty());
  const cv::Mat raw = cv::imread(frame.left_path, cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::norm(raw, frame.left, cv::NORM_L1), 0.0);
}

TEST(EurocReaderTest, ReadsAslGroundTruthWhenPresent) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, false);
  test::write_euroc_groundtruth_csv(test::euroc_fixture_dir() + "/groundtruth/body_tum.txt", root);
  const EurocReader reader(root);
  EXPECT_EQ(reader.size(), 5u);
  EXPECT_FALSE(reader.has_right());
  const auto gt = reader.ground_truth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 95u);
  EXPECT_NEAR(gt->stamps[0], 1403715273.26214, 1e-6);
  EXPECT_NEAR(gt->poses[0].translation().x(), 0.878895, 1e-12);
  EXPECT_NEAR(gt->poses[0].translation().z(), 0.948427, 1e-12);
  // body_tum.txt gives qx qy qz qw = -0.824237 -0.106942 -0.551702 0.069433.
  const Quat q = gt->poses[0].quaternion();
  EXPECT_NEAR(std::abs(q.w()), 0.069433, 1e-5);
  EXPECT_NEAR(q.x() * (q.w() > 0 ? 1 : -1), -0.824237, 1e-5);
}

TEST(EurocReaderTest, StereoPairsByTimestamp) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, true);
  // Drop the first cam1 frame: cam0's first frame loses its partner and is skipped.
  const std::string csv1 = root + "/mav0/cam1/data.csv";
  std::string text = test::read_text_file(csv1);
  const auto first_row = text.find('\n') + 1;
  text.erase(first_row, text.find('\n', first_row) + 1 - first_row);
  test::write_text_file(csv1, text);
  const EurocReader reader(root);
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_EQ(reader.timestamp_ns(0), 1403715273312143104);

  // No overlap at all is an error naming cam1's listing.
  test::write_text_file(csv1, "#timestamp [ns],filename\n1,1403715273312143104.png\n");
  expect_error_naming([&] { EurocReader r(root); }, csv1);
}

TEST(EurocReaderTest, MissingImageIsAnErrorNamingTheListing) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, false);
  const std::string image = root + "/mav0/cam0/data/1403715273362142976.png";
  fs::remove(image);
  try {
    EurocReader reader(root);
    FAIL();
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(root + "/mav0/cam0/data.csv:4"), std::string::npos) << message;
    EXPECT_NE(message.find(image), std::string::npos) << message;
  }
}

TEST(EurocReaderTest, MissingRightImageOfAPairIsAnError) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, true);
  const std::string image = root + "/mav0/cam1/data/1403715273412143104.png";
  fs::remove(image);
  expect_error_naming([&] { EurocReader r(root); }, root + "/mav0/cam1/data.csv:5");
  // A monocular reader does not need cam1.
  EXPECT_EQ(EurocReader(root, DatasetOptions{false, true}).size(), 5u);
}

TEST(EurocReaderTest, UnsortedOrDuplicateStampsAreErrors) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, false);
  const std::string csv = root + "/mav0/cam0/data.csv";
  const std::string header = "#timestamp [ns],filename\n";
  const std::string a = "1403715273262142976,1403715273262142976.png\n";
  const std::string b = "1403715273312143104,1403715273312143104.png\n";
  test::write_text_file(csv, header + b + a);
  expect_error_naming([&] { EurocReader r(root); }, csv + ":3");
  test::write_text_file(csv, header + a + a);
  expect_error_naming([&] { EurocReader r(root); }, "repeats");
  test::write_text_file(csv, header + "12x4,1403715273262142976.png\n");
  expect_error_naming([&] { EurocReader r(root); }, csv + ":2");
  test::write_text_file(csv, header);
  expect_error_naming([&] { EurocReader r(root); }, "empty sequence");
}

TEST(EurocReaderTest, MissingSensorYamlIsAnError) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 3, true);
  fs::remove(root + "/mav0/cam1/sensor.yaml");
  expect_error_naming([&] { EurocReader r(root); }, root + "/mav0/cam1/sensor.yaml");
  expect_error_naming([&] { EurocReader r(tmp.path().string()); }, "mav0");
}

Settings config_settings(const std::string& name) {
  return load_settings(std::string(SBASLAM_SOURCE_DIR) + "/config/" + name);
}

// A copy of the fixture's first frames with neither sensor.yaml: only a settings file calibrates
// it.
std::string copy_without_sensor_yaml(const TempDir& tmp, std::size_t frames) {
  const std::string root = test::copy_euroc_subset(tmp.path().string(), frames, true);
  fs::remove(root + "/mav0/cam0/sensor.yaml");
  fs::remove(root + "/mav0/cam1/sensor.yaml");
  return root;
}

DatasetOptions with_settings(const Settings& settings, bool load_right = true) {
  DatasetOptions options;
  options.load_right = load_right;
  options.settings = &settings;
  return options;
}

// ORB-SLAM3's EuRoC settings hold the calibration of the fixture's sensor.yaml files (as
// T_c1_c2), so the rig they give must be the one the sensor.yaml files give.
TEST(EurocReaderTest, WithoutSensorYamlTheSettingsCalibrateTheRig) {
  TempDir tmp;
  const std::string root = copy_without_sensor_yaml(tmp, 3);
  expect_error_naming([&] { EurocReader r(root); }, root + "/mav0/cam0/sensor.yaml");

  const Settings settings = config_settings("EuRoC_stereo.yaml");
  const EurocReader from_settings(root, with_settings(settings));
  const EurocReader from_sensors(test::euroc_fixture_dir());
  const DatasetCalibration a = *from_settings.calibration();
  const DatasetCalibration b = *from_sensors.calibration();
  ASSERT_TRUE(a.stereo && b.stereo);
  EXPECT_NEAR(a.stereo->baseline, b.stereo->baseline, 1e-9);
  EXPECT_NEAR(a.stereo->intrinsics.fx, b.stereo->intrinsics.fx, 1e-6);
  EXPECT_NEAR(a.stereo->intrinsics.cy, b.stereo->intrinsics.cy, 1e-6);
  EXPECT_LT((a.T_cam0_image.so3().inverse() * b.T_cam0_image.so3()).angle(), 1e-9);
  EXPECT_TRUE(a.T_body_cam0.matrix().isIdentity());  // unknown without sensor.yaml

  const FrameData frame = from_settings.load(2);
  const FrameData expected = from_sensors.load(2);
  EXPECT_LE(cv::norm(frame.left, expected.left, cv::NORM_INF), 1.0);
  EXPECT_LE(cv::norm(frame.right, expected.right, cv::NORM_INF), 1.0);

  // Monocular: the settings' distorted camera and the raw image.
  const Settings mono = config_settings("EuRoC_mono.yaml");
  const EurocReader raw(root, with_settings(mono, false));
  EXPECT_FALSE(raw.has_right());
  EXPECT_DOUBLE_EQ(raw.calibration()->camera.distortion.k1, mono.camera.distortion.k1);
  const FrameData raw_frame = raw.load(1);
  EXPECT_EQ(
      cv::norm(raw_frame.left, cv::imread(raw_frame.left_path, cv::IMREAD_GRAYSCALE), cv::NORM_INF),
      0.0);
}

TEST(EurocReaderTest, WithoutSensorYamlStereoNeedsASecondCameraInTheSettings) {
  TempDir tmp;
  const std::string root = copy_without_sensor_yaml(tmp, 3);
  const Settings mono = config_settings("EuRoC_mono.yaml");
  ASSERT_FALSE(mono.stereo.enabled);
  expect_error_naming([&] { EurocReader r(root, with_settings(mono)); }, mono.path);
  expect_error_naming([&] { EurocReader r(root, with_settings(mono)); }, "Camera2");

  // Stereo.b alone: a pair rectified before recording, returned as it is.
  Settings rectified = config_settings("EuRoC_mono.yaml");
  rectified.stereo.enabled = true;
  rectified.stereo.baseline = 0.11;
  expect_error_naming([&] { EurocReader r(root, with_settings(rectified)); }, "distortion");
  rectified.camera.distortion = RadTanDistortion{};
  const EurocReader pair(root, with_settings(rectified));
  ASSERT_TRUE(pair.has_right());
  EXPECT_DOUBLE_EQ(pair.calibration()->stereo->baseline, 0.11);
  EXPECT_DOUBLE_EQ(pair.calibration()->stereo->bf, 0.11 * rectified.camera.intrinsics.fx);
  const FrameData frame = pair.load(0);
  const std::string file = fs::path(frame.left_path).filename().string();
  EXPECT_EQ(cv::norm(frame.left, cv::imread(frame.left_path, cv::IMREAD_GRAYSCALE), cv::NORM_INF),
            0.0);
  EXPECT_EQ(
      cv::norm(frame.right, cv::imread(root + "/mav0/cam1/data/" + file, cv::IMREAD_GRAYSCALE),
               cv::NORM_INF),
      0.0);

  // sensor.yaml files, where present, are used and the settings are not.
  const std::string with_files = test::copy_euroc_subset(tmp.path().string() + "/b", 3, true);
  const EurocReader files(with_files, with_settings(mono));
  EXPECT_NEAR(files.calibration()->stereo->baseline, 0.110078, 1e-6);
}

// ORB-SLAM2's stereo file (LEFT.* / RIGHT.*) calibrates a recording without sensor.yaml: its
// rectification is applied (at alpha 0 it is the one sensor.yaml gives), and LEFT.* is the
// monocular camera; with sensor.yaml files they win, as for every other settings file.
TEST(EurocReaderTest, WithoutSensorYamlOrbSlam2sRectificationKeysRectifyThePair) {
  TempDir tmp;
  const std::string root = copy_without_sensor_yaml(tmp, 3);
  test::write_text_file(tmp.file("orbslam2.yaml"),
                        test::orbslam2_stereo_settings(test::euroc_fixture_rectification(0.0)));
  const Settings settings = load_settings(tmp.file("orbslam2.yaml"));
  const EurocReader from_settings(root, with_settings(settings));
  const EurocReader from_sensors(test::euroc_fixture_dir());
  const DatasetCalibration a = *from_settings.calibration();
  const DatasetCalibration b = *from_sensors.calibration();
  ASSERT_TRUE(a.stereo && b.stereo);
  EXPECT_NEAR(a.stereo->bf, b.stereo->bf, 1e-9);
  EXPECT_NEAR(a.camera.intrinsics.cx, b.camera.intrinsics.cx, 1e-9);
  EXPECT_TRUE(a.camera.distortion.is_zero());
  EXPECT_LT((a.T_cam0_image.so3().inverse() * b.T_cam0_image.so3()).angle(), 1e-12);
  const FrameData frame = from_settings.load(2);
  const FrameData expected = from_sensors.load(2);
  EXPECT_EQ(cv::norm(frame.left, expected.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(frame.right, expected.right, cv::NORM_INF), 0.0);

  const EurocReader mono(root, with_settings(settings, false));
  EXPECT_FALSE(mono.has_right());
  EXPECT_DOUBLE_EQ(mono.calibration()->camera.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(mono.calibration()->camera.distortion.k1, -0.28340811);

  test::write_text_file(tmp.file("wide.yaml"),
                        test::orbslam2_stereo_settings(test::euroc_fixture_rectification(1.0)));
  const Settings wide = load_settings(tmp.file("wide.yaml"));
  const EurocReader files(test::euroc_fixture_dir(), with_settings(wide));
  EXPECT_EQ(files.calibration()->stereo->intrinsics.fx, b.stereo->intrinsics.fx);
  EXPECT_NE(files.calibration()->stereo->intrinsics.fx, wide.camera.intrinsics.fx);
}

TEST(EurocReaderTest, TruncatedImageFailsOnLoadOnly) {
  TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 5, true);
  const std::string broken = root + "/mav0/cam1/data/1403715273412143104.png";
  test::truncate_file(broken, 1000);
  const EurocReader reader(root);
  EXPECT_NO_THROW(reader.load(0));
  expect_error_naming([&] { reader.load(3); }, broken);
}

}  // namespace
}  // namespace sbaslam::io
