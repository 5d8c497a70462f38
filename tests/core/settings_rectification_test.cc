// ORB-SLAM2's stereo settings (and ORB-SLAM3's before v1.0): the pair's rectification given as
// LEFT.* / RIGHT.* beside Camera.* of the rectified images.

#include <gtest/gtest.h>

#include <string>

#include "helper/expect_error.h"
#include "helper/orbslam2_stereo.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/settings.h"

namespace sbaslam {
namespace {

using test::expect_error_naming;
using test::TempDir;
using test::write_text_file;

// `text` with the whole line that starts with `key` replaced (or removed, for an empty line).
std::string replace_line(std::string text, const std::string& key, const std::string& line) {
  const std::size_t at = text.find("\n" + key) + 1;
  const std::size_t end = text.find('\n', at) + 1;
  return text.replace(at, end - at, line.empty() ? "" : line + "\n");
}

// `text` with the !!opencv-matrix block of `key` replaced by `block`.
std::string replace_matrix(std::string text, const std::string& key, const std::string& block) {
  const std::size_t at = text.find("\n" + key + ":") + 1;
  const std::size_t end = text.find("]\n", at) + 2;
  return text.replace(at, end - at, block);
}

Settings load_text(const TempDir& tmp, const std::string& text) {
  write_text_file(tmp.file("settings.yaml"), text);
  return load_settings(tmp.file("settings.yaml"));
}

TEST(SettingsRectification, ReadsOrbSlam2sLeftAndRightKeys) {
  TempDir tmp;
  const PrecomputedRectification expected = test::euroc_fixture_rectification(1.0);
  const Settings s = load_text(tmp, test::orbslam2_stereo_settings(expected));
  ASSERT_TRUE(s.stereo.precomputed.has_value());
  EXPECT_TRUE(s.stereo.needs_rectification());
  EXPECT_FALSE(s.stereo.right.has_value());
  const PrecomputedRectification& r = *s.stereo.precomputed;
  // The raw cameras are the fixture's sensor.yaml ones.
  EXPECT_DOUBLE_EQ(r.left.raw.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(r.left.raw.distortion.k1, -0.28340811);
  EXPECT_DOUBLE_EQ(r.right.raw.intrinsics.cx, 379.999);
  EXPECT_DOUBLE_EQ(r.right.raw.distortion.p2, -3.5559070e-05);
  EXPECT_EQ(r.left.raw.width, 752);
  EXPECT_EQ(r.right.raw.height, 480);
  EXPECT_TRUE(r.left.R.isApprox(expected.left.R, 1e-15));
  EXPECT_TRUE(r.right.P.isApprox(expected.right.P, 1e-15));
  // Camera.* and Camera.bf describe the rectified images.
  EXPECT_DOUBLE_EQ(s.camera.intrinsics.fx, expected.left.P(0, 0));
  EXPECT_DOUBLE_EQ(s.stereo.bf, -expected.right.P(0, 3));
  EXPECT_NEAR(s.stereo.baseline, 0.110078, 1e-6);
  EXPECT_DOUBLE_EQ(s.stereo.th_depth, 35.0);
}

TEST(SettingsRectification, FourDistortionCoefficientsAreReadToo) {
  TempDir tmp;
  const std::string text = replace_matrix(
      test::orbslam2_stereo_settings(test::euroc_fixture_rectification(0.0)), "RIGHT.D",
      "RIGHT.D: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: f\n   data: [-0.28, 0.07, "
      "-0.0001, 0.00003]\n");
  const Settings s = load_text(tmp, text);
  EXPECT_NEAR(s.stereo.precomputed->right.raw.distortion.k1, -0.28, 1e-7);
  EXPECT_NEAR(s.stereo.precomputed->right.raw.distortion.p2, 0.00003, 1e-10);
  EXPECT_EQ(s.stereo.precomputed->right.raw.distortion.k3, 0.0);
}

TEST(SettingsRectification, RefusesAnInconsistentOrIncompleteRectification) {
  TempDir tmp;
  const PrecomputedRectification rect = test::euroc_fixture_rectification(0.0);
  const std::string good = test::orbslam2_stereo_settings(rect);
  const std::string path = tmp.file("settings.yaml");
  const auto refused = [&](const std::string& text, const std::string& named) {
    SCOPED_TRACE(named);
    expect_error_naming([&] { load_text(tmp, text); }, path);
    expect_error_naming([&] { load_text(tmp, text); }, named);
  };
  refused(replace_matrix(good, "RIGHT.R", ""), "RIGHT.R");
  refused(replace_line(good, "LEFT.width", ""), "LEFT.width");
  refused(replace_line(good, "Camera.fx", "Camera.fx: 400.0"), "LEFT.P");
  refused(replace_line(good, "Camera.bf", "Camera.bf: 40.0"), "Camera.bf");
  refused(replace_line(good, "Camera.bf", ""), "Camera.bf");
  refused(replace_line(good, "Camera.k1", "Camera.k1: -0.28"), "distortion");
  refused(replace_line(good, "Camera.width", "Camera.width: 640"), "640");
  refused(replace_matrix(good, "LEFT.D",
                         "LEFT.D: !!opencv-matrix\n   rows: 1\n   cols: 3\n   dt: d\n   data: "
                         "[0.1, 0.2, 0.3]\n"),
          "LEFT.D");
  refused(replace_matrix(good, "LEFT.R",
                         "LEFT.R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: "
                         "[1, 0, 0, 0, 2, 0, 0, 0, 1]\n"),
          "LEFT.R");
  refused(replace_matrix(good, "RIGHT.K",
                         "RIGHT.K: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: "
                         "[457.6, 0, 380, 0, 456.1, 255.2, 0, 0, .nan]\n"),
          "RIGHT.K");
  // A second camera described twice.
  refused(good +
              "Camera2.fx: 457.587\nCamera2.fy: 456.134\nCamera2.cx: 379.999\n"
              "Camera2.cy: 255.238\nTlr: !!opencv-matrix\n   rows: 3\n   cols: 4\n   dt: f\n"
              "   data: [1, 0, 0, 0.11, 0, 1, 0, 0, 0, 0, 1, 0]\n",
          "Camera2");
}

TEST(SettingsRectification, SaveLoadRoundTripKeepsTheRectification) {
  TempDir tmp;
  const Settings original =
      load_text(tmp, test::orbslam2_stereo_settings(test::euroc_fixture_rectification(1.0)));
  save_settings(original, tmp.file("saved.yaml"));
  const Settings back = load_settings(tmp.file("saved.yaml"));
  ASSERT_TRUE(back.stereo.precomputed.has_value());
  const PrecomputedRectification& a = *original.stereo.precomputed;
  const PrecomputedRectification& b = *back.stereo.precomputed;
  EXPECT_EQ(a.left.R, b.left.R);
  EXPECT_EQ(a.right.P, b.right.P);
  EXPECT_DOUBLE_EQ(a.right.raw.distortion.k2, b.right.raw.distortion.k2);
  EXPECT_DOUBLE_EQ(a.left.raw.intrinsics.cy, b.left.raw.intrinsics.cy);
  EXPECT_EQ(a.left.raw.width, b.left.raw.width);
  EXPECT_NEAR(back.stereo.bf, original.stereo.bf, 1e-12 * original.stereo.bf);
}

}  // namespace
}  // namespace sbaslam
