#include "sbaslam/io/dataset_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "helper/expect_error.h"
#include "helper/fixture_copy.h"
#include "helper/orbslam2_stereo.h"
#include "helper/temp_dir.h"

namespace sbaslam::io {
namespace {

Settings config_settings(const std::string& name) {
  return load_settings(std::string(SBASLAM_SOURCE_DIR) + "/config/" + name);
}

TEST(DatasetGeometry, EurocCalibrationWinsOverTheSettingsFile) {
  const Settings settings = config_settings("EuRoC_stereo.yaml");
  const auto reader = make_dataset_reader("euroc", test::euroc_fixture_dir());
  const DatasetCalibration calib = reader->calibration().value();
  const DatasetGeometry g = resolve_geometry(settings, *reader, test::euroc_fixture_dir(), true);
  // The settings describe the raw cameras; the reader returns rectified images.
  EXPECT_NE(settings.camera.intrinsics.fx, calib.camera.intrinsics.fx);
  EXPECT_EQ(g.camera.intrinsics.fx, calib.camera.intrinsics.fx);
  EXPECT_TRUE(g.stereo.enabled);
  EXPECT_FALSE(g.stereo.right.has_value());  // already rectified
  EXPECT_EQ(g.stereo.bf, calib.stereo->bf);
  EXPECT_EQ(g.stereo.th_depth, settings.stereo.th_depth);
  EXPECT_GT(g.T_cam0_image.so3().angle(), 0.0);  // the rectification rotation
}

TEST(DatasetGeometry, KittiTakesCalibTxtWithoutRectification) {
  const Settings settings = config_settings("KITTI04-12.yaml");
  const auto reader = make_dataset_reader("kitti", test::kitti_fixture_sequence_dir());
  const DatasetCalibration calib = reader->calibration().value();
  const DatasetGeometry g =
      resolve_geometry(settings, *reader, test::kitti_fixture_sequence_dir(), false);
  EXPECT_EQ(g.camera.intrinsics.fx, calib.camera.intrinsics.fx);
  EXPECT_EQ(g.camera.intrinsics.cx, calib.camera.intrinsics.cx);
  EXPECT_EQ(g.camera.fps, calib.camera.fps);
  EXPECT_EQ(g.T_cam0_image.log().norm(), 0.0);  // KITTI images are the cameras' own
}

// A fisheye settings file cannot describe KITTI-layout images, whose calib.txt would override it.
TEST(DatasetGeometry, FisheyeSettingsOnKittiImagesAreRefused) {
  Settings settings = config_settings("KITTI04-12.yaml");
  settings.camera.model = CameraModel::kKannalaBrandt8;
  const std::string path = test::kitti_fixture_sequence_dir();
  const auto reader = make_dataset_reader("kitti", path);
  test::expect_error_naming([&] { resolve_geometry(settings, *reader, path, false); },
                            settings.path + ": Camera.type is \"KannalaBrandt8\", but the KITTI");
}

// ORB-SLAM2's LEFT.* / RIGHT.* rectify raw images; KITTI-layout images are rectified already and
// calib.txt would have replaced them without a word.
TEST(DatasetGeometry, PrecomputedRectificationOnKittiImagesIsRefused) {
  Settings settings = config_settings("KITTI04-12.yaml");
  settings.stereo.precomputed = test::euroc_fixture_rectification(0.0);
  const std::string path = test::kitti_fixture_sequence_dir();
  const auto reader = make_dataset_reader("kitti", path);
  test::expect_error_naming([&] { resolve_geometry(settings, *reader, path, false); },
                            settings.path + ": LEFT.* / RIGHT.* rectify raw images");
}

// A rig the reader rectified leaves nothing to rectify in the geometry a run uses.
TEST(DatasetGeometry, EurocReaderRectificationClearsThePrecomputedOne) {
  Settings settings = config_settings("EuRoC_stereo.yaml");
  settings.stereo.right.reset();
  settings.stereo.precomputed = test::euroc_fixture_rectification(1.0);
  const auto reader = make_dataset_reader("euroc", test::euroc_fixture_dir());
  const DatasetGeometry g = resolve_geometry(settings, *reader, test::euroc_fixture_dir(), true);
  EXPECT_FALSE(g.stereo.needs_rectification());
  EXPECT_EQ(g.stereo.bf, reader->calibration()->stereo->bf);
}

// Camera.newWidth / newHeight scale the dataset's own camera (calib.txt here), not the settings'.
TEST(DatasetGeometry, ResizeScalesTheDatasetsCameraFromItsImageSize) {
  Settings settings = config_settings("KITTI04-12.yaml");
  settings.resize = ImageResize{613, 0};
  const std::string path = test::kitti_fixture_sequence_dir();
  const auto reader = make_dataset_reader("kitti", path);
  const CameraSettings raw = reader->calibration()->camera;
  ASSERT_EQ(raw.width, 1226);
  const DatasetGeometry g = resolve_geometry(settings, *reader, path, false);
  ASSERT_TRUE(g.scaling.has_value());
  EXPECT_EQ(g.scaling->from, cv::Size(1226, 370));
  EXPECT_EQ(g.scaling->to, cv::Size(613, 370));
  EXPECT_EQ(g.camera.width, 613);
  EXPECT_EQ(g.camera.height, 370);
  EXPECT_DOUBLE_EQ(g.camera.intrinsics.fx, raw.intrinsics.fx / 2.0);
  EXPECT_DOUBLE_EQ(g.camera.intrinsics.fy, raw.intrinsics.fy);
  EXPECT_DOUBLE_EQ(g.camera.intrinsics.cx, (raw.intrinsics.cx + 0.5) / 2.0 - 0.5);
  EXPECT_DOUBLE_EQ(g.camera.intrinsics.cy, raw.intrinsics.cy);
  EXPECT_DOUBLE_EQ(g.stereo.bf, settings.stereo.bf / 2.0);  // the same baseline
}

TEST(DatasetGeometry, StereoWithoutRightImagesNamesTheDatasetFolder) {
  const Settings settings = config_settings("KITTI04-12.yaml");
  const std::string path = test::kitti_fixture_sequence_dir();
  const auto reader = make_dataset_reader("kitti", path);
  test::expect_error_naming([&] { resolve_geometry(settings, *reader, path, true); },
                            path + ": --sensor stereo needs right images");
}

// ORB-SLAM2's stereo file calibrates a recording without sensor.yaml: its monocular camera is
// LEFT.K, while Camera.fx is the rectified images'; the two come from one file and do not
// disagree. A calibration file of the dataset's own that does is reported.
TEST(DatasetGeometry, FxDisagreementIsTheDatasetFilesAgainstTheSettings) {
  test::TempDir tmp;
  const std::string root = test::copy_euroc_subset(tmp.path().string(), 3, false);
  std::filesystem::remove(root + "/mav0/cam0/sensor.yaml");
  test::write_text_file(tmp.file("orbslam2.yaml"),
                        test::orbslam2_stereo_settings(test::euroc_fixture_rectification(0.0)));
  const Settings orbslam2 = load_settings(tmp.file("orbslam2.yaml"));
  DatasetOptions options;
  options.load_right = false;
  options.settings = &orbslam2;
  const auto mono = make_dataset_reader("euroc", root, options);
  const DatasetCalibration from_settings = mono->calibration().value();
  EXPECT_TRUE(from_settings.from_settings);
  ASSERT_GT(std::abs(from_settings.camera.intrinsics.fx - orbslam2.camera.intrinsics.fx),
            0.01 * from_settings.camera.intrinsics.fx);
  EXPECT_FALSE(settings_fx_disagrees(orbslam2, from_settings));

  Settings off = config_settings("EuRoC_mono.yaml");
  const auto files = make_dataset_reader("euroc", test::euroc_fixture_dir(), options);
  const DatasetCalibration from_files = files->calibration().value();
  EXPECT_FALSE(from_files.from_settings);
  EXPECT_FALSE(settings_fx_disagrees(off, from_files));
  off.camera.intrinsics.fx *= 1.05;
  EXPECT_TRUE(settings_fx_disagrees(off, from_files));
}

}  // namespace
}  // namespace sbaslam::io
