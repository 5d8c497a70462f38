// ORB-SLAM3's Camera.newWidth / Camera.newHeight (image resizing before tracking).

#include <gtest/gtest.h>

#include <string>

#include "helper/expect_error.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/settings.h"

namespace sbaslam {
namespace {

using test::TempDir;

std::string kitti_settings() {
  return test::read_text_file(std::string(SBASLAM_SOURCE_DIR) + "/config/KITTI04-12.yaml");
}

Settings load_text(const TempDir& tmp, const std::string& text) {
  test::write_text_file(tmp.file("settings.yaml"), text);
  return load_settings(tmp.file("settings.yaml"));
}

TEST(SettingsResize, ReadsNewWidthAndNewHeightEitherAlone) {
  TempDir tmp;
  EXPECT_FALSE(load_text(tmp, kitti_settings()).resize.has_value());
  const Settings both =
      load_text(tmp, kitti_settings() + "Camera.newWidth: 620\nCamera.newHeight: 188\n");
  ASSERT_TRUE(both.resize.has_value());
  EXPECT_EQ(both.resize->width, 620);
  EXPECT_EQ(both.resize->height, 188);
  EXPECT_EQ(both.camera.width, 1241);  // Camera.width stays the images' own size
  const Settings height = load_text(tmp, kitti_settings() + "Camera.newHeight: 188\n");
  EXPECT_EQ(height.resize->width, 0);
  EXPECT_EQ(height.resize->height, 188);

  save_settings(both, tmp.file("saved.yaml"));
  const Settings back = load_settings(tmp.file("saved.yaml"));
  ASSERT_TRUE(back.resize.has_value());
  EXPECT_EQ(back.resize->width, 620);
  EXPECT_EQ(back.resize->height, 188);
}

TEST(SettingsResize, RefusesANonPositiveOrNonIntegerSize) {
  TempDir tmp;
  const std::string path = tmp.file("settings.yaml");
  for (const std::string line : {"Camera.newWidth: 0", "Camera.newWidth: 620.5",
                                 "Camera.newHeight: .nan", "Camera.newHeight: \"big\""}) {
    SCOPED_TRACE(line);
    const std::string key = line.substr(0, line.find(':'));
    test::expect_error_naming([&] { load_text(tmp, kitti_settings() + line + "\n"); },
                              path + ": '" + key + "'");
  }
}

}  // namespace
}  // namespace sbaslam
