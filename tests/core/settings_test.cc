#include "sbaslam/core/settings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"

namespace sbaslam {
namespace {

using test::TempDir;
using test::write_text_file;

// An ORB-SLAM2/3 "old keys" monocular/stereo file with keys we ignore (Viewer.*, IMU.*).
const char* kOldKeys = R"(%YAML:1.0
---
Camera.type: "PinHole"
Camera.fx: 718.856
Camera.fy: 718.856
Camera.cx: 607.1928
Camera.cy: 185.2157
Camera.k1: 0.1
Camera.k2: -0.2
Camera.p1: 0.001
Camera.p2: -0.002
Camera.k3: 0.05
Camera.width: 1241
Camera.height: 376
Camera.fps: 10.0
Camera.bf: 386.1448
Camera.RGB: 0
ThDepth: 35.0
DepthMapFactor: 5000.0
ORBextractor.nFeatures: 2000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
Viewer.KeyFrameSize: 0.6
Viewer.ViewpointF: 2000
IMU.NoiseGyro: 1.7e-4
Saliency.source: "none"
Saliency.model: "models/sal.onnx"
Saliency.a: 2.0
Saliency.b: 0.5
Saliency.map_ba_max_weight: 5.0
Saliency.map_ba_depth: "point"
Saliency.depth_a: 3.0
Saliency.depth_b: 0.25
Saliency.depth_near: 4.5
Saliency.saturation: 0.02
Saliency.depth: "none"
Mapping.mono_min_parallax_deg: 1.5
System.seed: 42
System.deterministic: 1
System.LoadAtlasFromFile: "maps/street"
System.SaveAtlasToFile: "maps/street_more"
)";

// ORB-SLAM3 v1.0, unrectified stereo (EuRoC style), single-precision matrix.
const char* kV1Stereo = R"(%YAML:1.0
---
File.version: "1.0"
Camera.type: "PinHole"
Camera1.fx: 458.654
Camera1.fy: 457.296
Camera1.cx: 367.215
Camera1.cy: 248.375
Camera1.k1: -0.28340811
Camera1.k2: 0.07395907
Camera1.p1: 0.00019359
Camera1.p2: 1.76187114e-05
Camera2.fx: 457.587
Camera2.fy: 456.134
Camera2.cx: 379.999
Camera2.cy: 255.238
Camera2.k1: -0.28368365
Camera2.k2: 0.07451284
Camera2.p1: -0.00010473
Camera2.p2: -3.55590700e-05
Camera.width: 752
Camera.height: 480
Camera.fps: 20
Camera.RGB: 1
Stereo.ThDepth: 60.0
Stereo.T_c1_c2: !!opencv-matrix
  rows: 4
  cols: 4
  dt: f
  data: [0.999997256477797,-0.002317135723275,-0.000343393120620,0.110074137800478,
         0.002312067192432,0.999898048507103,-0.014090668452683,-0.000156612054392,
         0.000375623981817,0.014089835846691,0.999900662638081,0.000889382785432,
         0,0,0,1.000000000000000]
ORBextractor.nFeatures: 1200
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
)";

// ORB-SLAM3 v1.0, a fisheye stereo pair as in its TUM-VI example: Kannala-Brandt coefficients
// k1..k4 under the pinhole keys' names, and the overlap columns we do not need.
const char* kV1Fisheye = R"(%YAML:1.0
---
File.version: "1.0"
Camera.type: "KannalaBrandt8"
Camera1.fx: 190.978477
Camera1.fy: 190.973307
Camera1.cx: 254.931706
Camera1.cy: 256.897442
Camera1.k1: 0.003482389402
Camera1.k2: 0.000715034845
Camera1.k3: -0.002053236141
Camera1.k4: 0.000202936736
Camera2.fx: 190.442369
Camera2.fy: 190.434387
Camera2.cx: 252.597621
Camera2.cy: 254.917213
Camera2.k1: 0.003400720715
Camera2.k2: 0.001766761649
Camera2.k3: -0.002664001124
Camera2.k4: 0.000333748919
Stereo.T_c1_c2: !!opencv-matrix
  rows: 4
  cols: 4
  dt: f
  data: [0.999994,0.001079,-0.003218,0.101160,
         -0.001067,0.999994,0.003498,0.001983,
         0.003222,-0.003494,0.999989,0.001045,
         0,0,0,1.000000]
Camera1.overlappingBegin: 0
Camera1.overlappingEnd: 511
Camera2.overlappingBegin: 0
Camera2.overlappingEnd: 511
Camera.width: 512
Camera.height: 512
Camera.fps: 20
Camera.RGB: 1
Stereo.ThDepth: 40.0
ORBextractor.nFeatures: 1000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
)";

// The same rig in the layout of ORB-SLAM3's files before v1.0 (its TUM-VI examples): "Camera"
// and "Camera2" keys, the pair's pose as a 3x4 "Tlr", and Camera.bf beside them.
const char* kOldFisheyeStereoCameras = R"(%YAML:1.0
---
Camera.type: "KannalaBrandt8"
Camera.fx: 190.978477
Camera.fy: 190.973307
Camera.cx: 254.931706
Camera.cy: 256.897442
Camera.k1: 0.003482389402
Camera.k2: 0.000715034845
Camera.k3: -0.002053236141
Camera.k4: 0.000202936736
Camera2.fx: 190.442369
Camera2.fy: 190.434387
Camera2.cx: 252.597621
Camera2.cy: 254.917213
Camera2.k1: 0.003400720715
Camera2.k2: 0.001766761649
Camera2.k3: -0.002664001124
Camera2.k4: 0.000333748919
)";
const char* kOldTlr = R"(Tlr: !!opencv-matrix
  rows: 3
  cols: 4
  dt: f
  data: [0.999994,0.001079,-0.003218,0.101160,
         -0.001067,0.999994,0.003498,0.001983,
         0.003222,-0.003494,0.999989,0.001045]
)";
const char* kOldFisheyeStereoRest = R"(Camera.lappingBegin: 0
Camera.lappingEnd: 511
Camera2.lappingBegin: 0
Camera2.lappingEnd: 511
Camera.width: 512
Camera.height: 512
Camera.fps: 20.0
Camera.bf: 19.3079
Camera.RGB: 1
ThDepth: 40.0
ORBextractor.nFeatures: 1000
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 20
ORBextractor.minThFAST: 7
)";

std::string old_fisheye_stereo(const std::string& tlr = kOldTlr) {
  return std::string(kOldFisheyeStereoCameras) + tlr + kOldFisheyeStereoRest;
}

std::string replace_line(std::string text, const std::string& key, const std::string& line) {
  const auto at = text.find("\n" + key + ":");
  if (at == std::string::npos) return text + line + "\n";
  const auto end = text.find('\n', at + 1);
  return text.replace(at + 1, end - at - 1, line);
}

TEST(SettingsTest, ReadsOldKeys) {
  TempDir tmp;
  write_text_file(tmp.file("old.yaml"), kOldKeys);
  const Settings s = load_settings(tmp.file("old.yaml"));
  EXPECT_EQ(s.path, tmp.file("old.yaml"));
  EXPECT_DOUBLE_EQ(s.camera.intrinsics.fx, 718.856);
  EXPECT_DOUBLE_EQ(s.camera.intrinsics.cy, 185.2157);
  EXPECT_DOUBLE_EQ(s.camera.distortion.k1, 0.1);
  EXPECT_DOUBLE_EQ(s.camera.distortion.p2, -0.002);
  EXPECT_DOUBLE_EQ(s.camera.distortion.k3, 0.05);
  EXPECT_EQ(s.camera.width, 1241);
  EXPECT_EQ(s.camera.height, 376);
  EXPECT_DOUBLE_EQ(s.camera.fps, 10.0);
  EXPECT_FALSE(s.camera.rgb);
  EXPECT_TRUE(s.stereo.enabled);
  EXPECT_FALSE(s.stereo.needs_rectification());
  EXPECT_DOUBLE_EQ(s.stereo.bf, 386.1448);
  EXPECT_NEAR(s.stereo.baseline, 386.1448 / 718.856, 1e-15);
  EXPECT_DOUBLE_EQ(s.stereo.th_depth, 35.0);
  EXPECT_DOUBLE_EQ(s.rgbd.depth_map_factor, 5000.0);
  EXPECT_EQ(s.orb.n_features, 2000);
  EXPECT_DOUBLE_EQ(s.orb.scale_factor, 1.2);
  EXPECT_EQ(s.orb.n_levels, 8);
  EXPECT_EQ(s.orb.ini_th_fast, 20);
  EXPECT_EQ(s.orb.min_th_fast, 7);
  EXPECT_EQ(s.saliency.source, "none");
  EXPECT_EQ(s.saliency.model_path, "models/sal.onnx");
  EXPECT_DOUBLE_EQ(s.saliency.weight_a, 2.0);
  EXPECT_DOUBLE_EQ(s.saliency.weight_b, 0.5);
  EXPECT_DOUBLE_EQ(s.saliency.map_ba_max_weight, 5.0);
  EXPECT_DOUBLE_EQ(s.saliency.map_ba_weight_scale(), 2.0);  // the largest weight 2.5 -> 5
  EXPECT_EQ(s.saliency.map_ba_depth, "point");
  EXPECT_DOUBLE_EQ(s.saliency.depth_a, 3.0);
  EXPECT_DOUBLE_EQ(s.saliency.depth_b, 0.25);
  EXPECT_EQ(s.saliency.depth_near, std::optional<double>(4.5));
  EXPECT_DOUBLE_EQ(s.saliency.saturation, 0.02);
  EXPECT_EQ(s.saliency.depth_source, "none");
  EXPECT_EQ(s.mapping.mono_min_parallax_deg, std::optional<double>(1.5));
  EXPECT_EQ(s.system.seed, 42u);
  EXPECT_TRUE(s.system.deterministic);
  EXPECT_EQ(s.system.load_atlas, "maps/street");
  EXPECT_EQ(s.system.save_atlas, "maps/street_more");
}

// "auto" weighs local and full BA by each point's depth on monocular rigs only; "point" and
// "frame" on every rig; never without a depth correction.
TEST(SettingsTest, MapBaDepthResolvesPerRig) {
  SaliencySettings s;
  EXPECT_TRUE(s.map_ba_point_depth(false));
  EXPECT_FALSE(s.map_ba_point_depth(true));
  s.map_ba_depth = "point";
  EXPECT_TRUE(s.map_ba_point_depth(true));
  s.depth_source = "none";
  EXPECT_FALSE(s.map_ba_point_depth(false));
  s.depth_source = "auto";
  s.map_ba_depth = "frame";
  EXPECT_FALSE(s.map_ba_point_depth(false));
}

TEST(SettingsTest, OptionalKeysTakeDefaults) {
  TempDir tmp;
  std::string text = kOldKeys;
  for (const char* key : {"Camera.bf",
                          "ThDepth",
                          "DepthMapFactor",
                          "Camera.k3",
                          "Camera.fps",
                          "Camera.RGB",
                          "Saliency.source",
                          "Saliency.model",
                          "Saliency.a",
                          "Saliency.b",
                          "Saliency.depth_a",
                          "Saliency.depth_b",
                          "Saliency.depth_near",
                          "Saliency.saturation",
                          "Saliency.depth",
                          "Saliency.map_ba_max_weight",
                          "Saliency.map_ba_depth",
                          "Mapping.mono_min_parallax_deg",
                          "System.seed",
                          "System.deterministic",
                          "System.LoadAtlasFromFile",
                          "System.SaveAtlasToFile"})
    text = replace_line(text, key, "");
  write_text_file(tmp.file("mono.yaml"), text);
  const Settings s = load_settings(tmp.file("mono.yaml"));
  const SaliencySettings defaults;
  EXPECT_FALSE(s.stereo.enabled);
  EXPECT_DOUBLE_EQ(s.camera.distortion.k3, 0.0);
  EXPECT_DOUBLE_EQ(s.camera.fps, 30.0);  // ORB-SLAM3's fallback
  EXPECT_TRUE(s.camera.rgb);
  EXPECT_DOUBLE_EQ(s.rgbd.depth_map_factor, 1.0);
  EXPECT_EQ(s.saliency.source, defaults.source);
  EXPECT_DOUBLE_EQ(s.saliency.weight_a, defaults.weight_a);
  EXPECT_DOUBLE_EQ(s.saliency.map_ba_max_weight, 16.0);
  EXPECT_DOUBLE_EQ(s.saliency.map_ba_weight_scale(), 16.0 / 257.0);
  EXPECT_EQ(s.saliency.map_ba_depth, "auto");
  EXPECT_FALSE(s.saliency.depth_near.has_value());  // the rig's close-point threshold
  EXPECT_DOUBLE_EQ(s.saliency.saturation, defaults.saturation);
  EXPECT_FALSE(s.mapping.mono_min_parallax_deg.has_value());  // ORB-SLAM's gate
  EXPECT_EQ(s.system.seed, 0u);
  EXPECT_FALSE(s.system.deterministic);
  EXPECT_TRUE(s.system.load_atlas.empty());
  EXPECT_TRUE(s.system.save_atlas.empty());
  EXPECT_TRUE(s.loop_closing.enabled);                  // ORB-SLAM3's default
  EXPECT_TRUE(s.loop_closing.vocabulary_path.empty());  // the shipped vocabulary
  EXPECT_TRUE(s.loop_closing.merge_maps);
}

TEST(SettingsTest, ReadsOrbSlam3sLoopClosingKey) {
  TempDir tmp;
  write_text_file(tmp.file("on.yaml"), replace_line(kOldKeys, "loopClosing", "loopClosing: 1") +
                                           "LoopClosing.vocabulary: \"/v/orb.bin\"\n");
  const Settings on = load_settings(tmp.file("on.yaml"));
  EXPECT_TRUE(on.loop_closing.enabled);
  EXPECT_EQ(on.loop_closing.vocabulary_path, "/v/orb.bin");
  write_text_file(tmp.file("off.yaml"), replace_line(kOldKeys, "loopClosing", "loopClosing: 0"));
  EXPECT_FALSE(load_settings(tmp.file("off.yaml")).loop_closing.enabled);
  write_text_file(tmp.file("no_merge.yaml"), kOldKeys + std::string("LoopClosing.merge_maps: 0\n"));
  EXPECT_FALSE(load_settings(tmp.file("no_merge.yaml")).loop_closing.merge_maps);
}

TEST(SettingsTest, ReadsVersion1UnrectifiedStereo) {
  TempDir tmp;
  write_text_file(tmp.file("v1.yaml"), kV1Stereo);
  const Settings s = load_settings(tmp.file("v1.yaml"));
  EXPECT_DOUBLE_EQ(s.camera.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(s.camera.distortion.k1, -0.28340811);
  EXPECT_DOUBLE_EQ(s.camera.fps, 20.0);
  ASSERT_TRUE(s.stereo.right.has_value());
  EXPECT_TRUE(s.stereo.needs_rectification());
  EXPECT_DOUBLE_EQ(s.stereo.right->intrinsics.cx, 379.999);
  EXPECT_DOUBLE_EQ(s.stereo.right->distortion.p2, -3.55590700e-05);
  EXPECT_EQ(s.stereo.right->width, 752);
  EXPECT_NEAR(s.stereo.T_c1_c2.translation().x(), 0.110074137800478, 1e-7);
  EXPECT_NEAR(s.stereo.T_c1_c2.translation().z(), 0.000889382785432, 1e-7);
  EXPECT_NEAR(s.stereo.baseline, 0.11007784, 1e-6);
  EXPECT_DOUBLE_EQ(s.stereo.bf, 0.0);  // set by rectification
  EXPECT_DOUBLE_EQ(s.stereo.th_depth, 60.0);
  EXPECT_EQ(s.orb.n_features, 1200);
}

TEST(SettingsTest, ReadsVersion1FisheyeStereo) {
  TempDir tmp;
  write_text_file(tmp.file("fisheye.yaml"), kV1Fisheye);
  const Settings s = load_settings(tmp.file("fisheye.yaml"));
  EXPECT_EQ(s.camera.model, CameraModel::kKannalaBrandt8);
  EXPECT_DOUBLE_EQ(s.camera.intrinsics.fx, 190.978477);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k1, 0.003482389402);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k4, 0.000202936736);
  EXPECT_TRUE(s.camera.distortion.is_zero());
  ASSERT_TRUE(s.stereo.needs_rectification());
  EXPECT_EQ(s.stereo.right->model, CameraModel::kKannalaBrandt8);
  EXPECT_DOUBLE_EQ(s.stereo.right->fisheye.k3, -0.002664001124);
  EXPECT_NEAR(s.stereo.baseline, 0.10118, 1e-4);
}

TEST(SettingsTest, ReadsOldLayoutFisheyeStereoAsTheVersion1File) {
  TempDir tmp;
  write_text_file(tmp.file("v1.yaml"), kV1Fisheye);
  write_text_file(tmp.file("old.yaml"), old_fisheye_stereo());
  const Settings v1 = load_settings(tmp.file("v1.yaml"));
  const Settings old = load_settings(tmp.file("old.yaml"));
  ASSERT_TRUE(old.stereo.needs_rectification());
  EXPECT_EQ(old.camera.model, CameraModel::kKannalaBrandt8);
  EXPECT_EQ(old.stereo.right->model, CameraModel::kKannalaBrandt8);
  EXPECT_DOUBLE_EQ(old.stereo.right->intrinsics.fx, v1.stereo.right->intrinsics.fx);
  EXPECT_DOUBLE_EQ(old.stereo.right->fisheye.k4, v1.stereo.right->fisheye.k4);
  EXPECT_TRUE(old.stereo.T_c1_c2.matrix().isApprox(v1.stereo.T_c1_c2.matrix(), 1e-12));
  EXPECT_DOUBLE_EQ(old.stereo.baseline, v1.stereo.baseline);
  // Camera.bf describes no rectified pair here: rectification decides it.
  EXPECT_EQ(old.stereo.bf, 0.0);
  EXPECT_DOUBLE_EQ(old.stereo.th_depth, 40.0);

  // ORB-SLAM3 wants Tlr as 3x4; a 4x4 or a missing one is refused, naming the key.
  const std::string square = old_fisheye_stereo(
      "Tlr: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
      "  data: [1,0,0,0.1, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n");
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"square.yaml", square},
                                   {"missing.yaml", old_fisheye_stereo("")}}) {
    write_text_file(tmp.file(name), text);
    try {
      load_settings(tmp.file(name));
      ADD_FAILURE() << "no error for " << name;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(tmp.file(name)), std::string::npos) << message;
      EXPECT_NE(message.find("'Tlr'"), std::string::npos) << message;
    }
  }
}

// ORB-SLAM3's inertial files give cam0's pose in the IMU frame: IMU.T_b_c1, or Tbc before v1.0.
TEST(SettingsTest, ReadsTheCameraPoseInTheImuFrame) {
  TempDir tmp;
  const std::string pose =
      "!!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
      "  data: [0.0, -1.0, 0.0, -0.05, 1.0, 0.0, 0.0, 0.01, 0.0, 0.0, 1.0, 0.02, 0.0, 0.0, 0.0, "
      "1.0]\n";
  write_text_file(tmp.file("v1.yaml"), std::string(kV1Fisheye) + "IMU.T_b_c1: " + pose);
  write_text_file(tmp.file("old.yaml"), old_fisheye_stereo() + "Tbc: " + pose);
  write_text_file(tmp.file("none.yaml"), kV1Fisheye);
  for (const char* name : {"v1.yaml", "old.yaml"}) {
    SCOPED_TRACE(name);
    const Settings s = load_settings(tmp.file(name));
    ASSERT_TRUE(s.T_body_cam0.has_value());
    EXPECT_NEAR(s.T_body_cam0->translation().x(), -0.05, 1e-7);  // dt: f
    // The camera's x axis is the body's y axis.
    EXPECT_TRUE((s.T_body_cam0->so3() * Vec3::UnitX()).isApprox(Vec3::UnitY(), 1e-12));
  }
  EXPECT_FALSE(load_settings(tmp.file("none.yaml")).T_body_cam0.has_value());

  const std::string sheared =
      "!!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n"
      "  data: [1.0, 0.5, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\n";
  write_text_file(tmp.file("sheared.yaml"), std::string(kV1Fisheye) + "IMU.T_b_c1: " + sheared);
  try {
    load_settings(tmp.file("sheared.yaml"));
    ADD_FAILURE() << "no error for a matrix that is not a pose";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(tmp.file("sheared.yaml")), std::string::npos) << message;
    EXPECT_NE(message.find("IMU.T_b_c1"), std::string::npos) << message;
  }
}

TEST(SettingsTest, ReadsOldKeysFisheye) {
  TempDir tmp;
  const std::string text =
      replace_line(kOldKeys, "Camera.type", "Camera.type: \"KannalaBrandt8\"") +
      "Camera.k4: 0.0004\n";
  write_text_file(tmp.file("old_fisheye.yaml"), text);
  const Settings s = load_settings(tmp.file("old_fisheye.yaml"));
  EXPECT_EQ(s.camera.model, CameraModel::kKannalaBrandt8);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k1, 0.1);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k2, -0.2);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k3, 0.05);
  EXPECT_DOUBLE_EQ(s.camera.fisheye.k4, 0.0004);

  // Kannala-Brandt needs all four coefficients, as in ORB-SLAM3.
  const std::string without_k4 = replace_line(text, "Camera.k4", "");
  write_text_file(tmp.file("no_k4.yaml"), without_k4);
  try {
    load_settings(tmp.file("no_k4.yaml"));
    ADD_FAILURE() << "no error without Camera.k4";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(tmp.file("no_k4.yaml")), std::string::npos) << message;
    EXPECT_NE(message.find("Camera.k4"), std::string::npos) << message;
  }
}

// v1.0 rectified stereo: Stereo.b instead of Camera2 and T_c1_c2.
std::string v1_rectified_text() {
  std::string text = kV1Stereo;
  for (const char* key : {"Camera2.fx", "Camera2.fy", "Camera2.cx", "Camera2.cy"})
    text = replace_line(text, key, "");
  text = replace_line(text, "Camera.type", "Camera.type: \"Rectified\"");
  return text + "Stereo.b: 0.0745\nRGBD.DepthMapFactor: 1000.0\n";
}

std::string base_text(const std::string& name) {
  if (name == "old") return kOldKeys;
  if (name == "v1") return kV1Stereo;
  return v1_rectified_text();
}

TEST(SettingsTest, ReadsVersion1RectifiedBaseline) {
  TempDir tmp;
  const std::string text = v1_rectified_text();
  write_text_file(tmp.file("v1b.yaml"), text);
  const Settings s = load_settings(tmp.file("v1b.yaml"));
  EXPECT_FALSE(s.stereo.right.has_value());
  EXPECT_DOUBLE_EQ(s.stereo.baseline, 0.0745);
  EXPECT_DOUBLE_EQ(s.stereo.bf, 0.0745 * 458.654);
  EXPECT_DOUBLE_EQ(s.rgbd.depth_map_factor, 1000.0);
}

TEST(SettingsTest, LoadsEveryShippedConfig) {
  const std::filesystem::path config_dir = std::filesystem::path(SBASLAM_SOURCE_DIR) / "config";
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(config_dir)) {
    if (entry.path().extension() != ".yaml") continue;
    names.push_back(entry.path().filename().string());
    SCOPED_TRACE(entry.path().string());
    const Settings s = load_settings(entry.path().string());
    EXPECT_GT(s.camera.intrinsics.fx, 0.0);
    EXPECT_GT(s.camera.width, 0);
  }
  for (const char* name : {"KITTI00-02.yaml", "KITTI03.yaml", "KITTI04-12.yaml", "EuRoC_mono.yaml",
                           "EuRoC_stereo.yaml", "TUM1.yaml", "TUM2.yaml", "TUM3.yaml"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;

  const auto load = [&](const char* name) { return load_settings((config_dir / name).string()); };
  const Settings kitti = load("KITTI04-12.yaml");
  EXPECT_DOUBLE_EQ(kitti.camera.intrinsics.fx, 707.0912);
  EXPECT_DOUBLE_EQ(kitti.camera.intrinsics.cy, 183.1104);
  EXPECT_DOUBLE_EQ(kitti.stereo.bf, 379.8145);
  EXPECT_NEAR(kitti.stereo.baseline, 0.53715, 1e-5);
  EXPECT_EQ(kitti.camera.width, 1241);
  EXPECT_EQ(kitti.orb.n_features, 2000);
  EXPECT_DOUBLE_EQ(load("KITTI03.yaml").stereo.bf, 387.5744);
  EXPECT_DOUBLE_EQ(load("KITTI00-02.yaml").camera.intrinsics.cx, 607.1928);

  const Settings euroc = load("EuRoC_stereo.yaml");
  ASSERT_TRUE(euroc.stereo.right.has_value());
  EXPECT_NEAR(euroc.stereo.baseline, 0.110078, 1e-6);
  EXPECT_DOUBLE_EQ(euroc.stereo.right->intrinsics.fx, 457.587);
  EXPECT_DOUBLE_EQ(euroc.stereo.th_depth, 60.0);
  const Settings euroc_mono = load("EuRoC_mono.yaml");
  EXPECT_FALSE(euroc_mono.stereo.enabled);
  EXPECT_DOUBLE_EQ(euroc_mono.camera.distortion.p2, 1.76187114e-05);

  const Settings tum1 = load("TUM1.yaml");
  EXPECT_DOUBLE_EQ(tum1.camera.distortion.k3, 1.163314);
  EXPECT_DOUBLE_EQ(tum1.rgbd.depth_map_factor, 5000.0);
  EXPECT_DOUBLE_EQ(tum1.stereo.bf, 40.0);
  EXPECT_DOUBLE_EQ(load("TUM2.yaml").camera.intrinsics.fy, 521.007327);
  EXPECT_TRUE(load("TUM3.yaml").camera.distortion.is_zero());
}

struct InvalidCase {
  const char* base;  // "old", "v1" (unrectified stereo) or "v1b" (rectified, Stereo.b)
  const char* key;   // the key the message must name
  const char* line;  // replacement line ("" removes the key)
};

class SettingsInvalidTest : public ::testing::TestWithParam<InvalidCase> {};

TEST_P(SettingsInvalidTest, ErrorNamesKeyAndFile) {
  const InvalidCase& c = GetParam();
  TempDir tmp;
  const std::string path = tmp.file("bad.yaml");
  write_text_file(path, replace_line(base_text(c.base), c.key, c.line));
  try {
    load_settings(path);
    FAIL() << "no error for '" << c.line << "'";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(c.key), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllCases, SettingsInvalidTest,
    ::testing::Values(
        InvalidCase{"old", "Camera.fx", "Camera.fx: .nan"},
        InvalidCase{"old", "Camera.fx", "Camera.fx: nan"},
        InvalidCase{"old", "Camera.fy", "Camera.fy: .inf"},
        InvalidCase{"old", "Camera.fx", "Camera.fx: -718.0"},
        InvalidCase{"old", "Camera.fy", "Camera.fy: 0.0"},
        InvalidCase{"old", "Camera.cx", "Camera.cx: abc"}, InvalidCase{"old", "Camera.fx", ""},
        InvalidCase{"old", "Camera.k1", "Camera.k1: .nan"},
        InvalidCase{"old", "Camera.width", "Camera.width: 0"},
        InvalidCase{"old", "Camera.height", "Camera.height: -376"},
        InvalidCase{"old", "Camera.height", ""}, InvalidCase{"old", "Camera.fps", "Camera.fps: 0"},
        InvalidCase{"old", "Camera.bf", "Camera.bf: 0.0"},
        InvalidCase{"old", "Camera.bf", "Camera.bf: -386.1"}, InvalidCase{"old", "ThDepth", ""},
        InvalidCase{"old", "DepthMapFactor", "DepthMapFactor: 0"},
        InvalidCase{"old", "ORBextractor.nLevels", "ORBextractor.nLevels: 0"},
        InvalidCase{"old", "ORBextractor.nLevels", "ORBextractor.nLevels: 2.5"},
        InvalidCase{"old", "ORBextractor.scaleFactor", "ORBextractor.scaleFactor: 1.0"},
        InvalidCase{"old", "ORBextractor.nFeatures", ""},
        InvalidCase{"old", "ORBextractor.minThFAST", "ORBextractor.minThFAST: 30"},
        InvalidCase{"old", "Saliency.b", "Saliency.b: 0.0"},
        InvalidCase{"old", "Saliency.depth", "Saliency.depth: \"lidar\""},
        InvalidCase{"old", "Saliency.depth", "Saliency.depth: \"model\""},  // no depth_model
        InvalidCase{"old", "Saliency.a", "Saliency.a: .nan"},
        InvalidCase{"old", "Saliency.map_ba_max_weight", "Saliency.map_ba_max_weight: -1.0"},
        InvalidCase{"old", "Saliency.map_ba_max_weight", "Saliency.map_ba_max_weight: .inf"},
        InvalidCase{"old", "Saliency.map_ba_depth", "Saliency.map_ba_depth: \"pixel\""},
        InvalidCase{"old", "Saliency.depth_near", "Saliency.depth_near: -1.0"},
        InvalidCase{"old", "Saliency.depth_near", "Saliency.depth_near: \"far\""},
        InvalidCase{"old", "Saliency.depth_near", "Saliency.depth_near: .nan"},
        InvalidCase{"old", "Saliency.saturation", "Saliency.saturation: 0.0"},
        InvalidCase{"old", "Saliency.saturation", "Saliency.saturation: 1.5"},
        InvalidCase{"old", "Saliency.keypoint_floor", "Saliency.keypoint_floor: -0.1"},
        InvalidCase{"old", "Saliency.keypoint_floor", "Saliency.keypoint_floor: .nan"},
        InvalidCase{"old", "Saliency.keypoint_max_dropped_share",
                    "Saliency.keypoint_max_dropped_share: 1.0"},
        InvalidCase{"old", "Mapping.mono_min_parallax_deg", "Mapping.mono_min_parallax_deg: 0"},
        InvalidCase{"old", "Mapping.mono_min_parallax_deg", "Mapping.mono_min_parallax_deg: 90"},
        InvalidCase{"old", "Mapping.mono_min_parallax_deg", "Mapping.mono_min_parallax_deg: .nan"},
        InvalidCase{"old", "System.seed", "System.seed: -1"},
        InvalidCase{"old", "System.deterministic", "System.deterministic: 2"},
        InvalidCase{"old", "loopClosing", "loopClosing: 2"},
        // cv::FileStorage would read the first copy and ignore the second without a word.
        InvalidCase{"old", "Camera.fx", "Camera.fx: 718.856\nCamera.fx: 700.0"},
        InvalidCase{"old", "Saliency.a", "Saliency.a: 256.0\nSaliency.a: 16.0"},
        InvalidCase{"old", "Camera.type", "Camera.type: \"Fisheye\""},
        InvalidCase{"v1", "Camera.type", ""},
        InvalidCase{"v1", "File.version", "File.version: \"2.0\""},
        InvalidCase{"v1", "Camera1.fx", "Camera1.fx: .nan"},
        InvalidCase{"v1", "Camera2.fy", "Camera2.fy: -1.0"},
        InvalidCase{"v1", "Stereo.ThDepth", ""}, InvalidCase{"v1b", "Stereo.b", "Stereo.b: 0.0"},
        InvalidCase{"v1b", "Stereo.b", "Stereo.b: -0.07"},
        InvalidCase{"v1b", "RGBD.DepthMapFactor", "RGBD.DepthMapFactor: .nan"}));

// Saliency.depth "model" and its keys: each bad value is named with the file.
TEST(SettingsTest, DepthModelKeysAreCheckedWithMessagesNamingThem) {
  const std::string model = "Saliency.depth: \"model\"\nSaliency.depth_model: \"d.onnx\"\n";
  const std::string size = "Saliency.depth_model_width: 64\nSaliency.depth_model_height: 32\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"Saliency.depth_model_width", model},
      {"Saliency.depth_model_channels", model + size + "Saliency.depth_model_channels: 2"},
      {"Saliency.depth_model_output", model + size + "Saliency.depth_model_output: \"disparity\""}};
  for (const auto& [key, lines] : cases) {
    TempDir tmp;
    const std::string path = tmp.file("bad.yaml");
    write_text_file(path, replace_line(base_text("old"), "Saliency.depth", lines));
    try {
      load_settings(path);
      ADD_FAILURE() << "no error for " << key;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(key), std::string::npos) << message;
    }
  }
  TempDir tmp;
  write_text_file(tmp.file("ok.yaml"),
                  replace_line(base_text("old"), "Saliency.depth",
                               model + size + "Saliency.depth_model_output: \"depth\""));
  const Settings s = load_settings(tmp.file("ok.yaml"));
  EXPECT_EQ(s.saliency.depth_source, "model");
  EXPECT_EQ(s.saliency.depth_model.path, "d.onnx");
  EXPECT_EQ(s.saliency.depth_model.width, 64);
  EXPECT_EQ(s.saliency.depth_model.height, 32);
  EXPECT_EQ(s.saliency.depth_model.channels, 3);
  EXPECT_FALSE(s.saliency.depth_model.inverse);
}

// Edits of the T_c1_c2 block that replace_line() cannot express.
TEST(SettingsTest, InvalidStereoTransformNamesKeyAndFile) {
  const std::string matrix_start = "Stereo.T_c1_c2: !!opencv-matrix";
  const std::string matrix_end = "1.000000000000000]";
  std::string zero_baseline = kV1Stereo;
  for (const char* value : {"0.110074137800478", "-0.000156612054392", "0.000889382785432"})
    zero_baseline.replace(zero_baseline.find(value), std::string(value).size(), "0.0");
  const auto with_matrix = [&](const std::string& block) {
    std::string text = kV1Stereo;
    const auto begin = text.find(matrix_start);
    const auto end = text.find(matrix_end) + matrix_end.size();
    return text.replace(begin, end - begin, block);
  };
  const std::vector<std::string> texts = {
      zero_baseline, with_matrix("Stereo.T_c1_c2: 3.0"),
      with_matrix("Stereo.T_c1_c2: !!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n  data: "
                  "[1, 0, 0, 0, 1, 0, 0, 0, 1]"),
      with_matrix("Stereo.T_c1_c2: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: d\n  data: "
                  "[2, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]"),
      with_matrix("Stereo.T_c1_c2: !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: d\n  data: "
                  "[1, 0, 0, .nan, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]")};
  TempDir tmp;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    const std::string path = tmp.file("bad" + std::to_string(i) + ".yaml");
    write_text_file(path, texts[i]);
    try {
      load_settings(path);
      ADD_FAILURE() << "no error for case " << i;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("Stereo.T_c1_c2"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(SettingsTest, MissingOrUnparsableFileNamesTheFile) {
  TempDir tmp;
  const std::string missing = tmp.file("nope.yaml");
  try {
    load_settings(missing);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos);
  }
  const std::string garbage = tmp.file("garbage.yaml");
  write_text_file(garbage, "%YAML:1.0\n---\nCamera.fx: [1, 2\n  : : {\n");
  try {
    load_settings(garbage);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(garbage), std::string::npos) << e.what();
  }
}

void expect_same(const Settings& a, const Settings& b) {
  ASSERT_EQ(a.T_body_cam0.has_value(), b.T_body_cam0.has_value());
  if (a.T_body_cam0) {
    EXPECT_TRUE(a.T_body_cam0->matrix().isApprox(b.T_body_cam0->matrix(), 1e-15));
  }
  EXPECT_DOUBLE_EQ(a.camera.intrinsics.fx, b.camera.intrinsics.fx);
  EXPECT_DOUBLE_EQ(a.camera.intrinsics.fy, b.camera.intrinsics.fy);
  EXPECT_DOUBLE_EQ(a.camera.intrinsics.cx, b.camera.intrinsics.cx);
  EXPECT_DOUBLE_EQ(a.camera.intrinsics.cy, b.camera.intrinsics.cy);
  EXPECT_DOUBLE_EQ(a.camera.distortion.k1, b.camera.distortion.k1);
  EXPECT_DOUBLE_EQ(a.camera.distortion.k2, b.camera.distortion.k2);
  EXPECT_DOUBLE_EQ(a.camera.distortion.p1, b.camera.distortion.p1);
  EXPECT_DOUBLE_EQ(a.camera.distortion.p2, b.camera.distortion.p2);
  EXPECT_DOUBLE_EQ(a.camera.distortion.k3, b.camera.distortion.k3);
  EXPECT_EQ(a.camera.model, b.camera.model);
  EXPECT_DOUBLE_EQ(a.camera.fisheye.k1, b.camera.fisheye.k1);
  EXPECT_DOUBLE_EQ(a.camera.fisheye.k4, b.camera.fisheye.k4);
  EXPECT_EQ(a.camera.width, b.camera.width);
  EXPECT_EQ(a.camera.height, b.camera.height);
  EXPECT_DOUBLE_EQ(a.camera.fps, b.camera.fps);
  EXPECT_EQ(a.camera.rgb, b.camera.rgb);
  EXPECT_EQ(a.stereo.enabled, b.stereo.enabled);
  EXPECT_DOUBLE_EQ(a.stereo.baseline, b.stereo.baseline);
  EXPECT_NEAR(a.stereo.bf, b.stereo.bf, 1e-12 * std::abs(a.stereo.bf));
  EXPECT_DOUBLE_EQ(a.stereo.th_depth, b.stereo.th_depth);
  ASSERT_EQ(a.stereo.right.has_value(), b.stereo.right.has_value());
  if (a.stereo.right) {
    EXPECT_DOUBLE_EQ(a.stereo.right->intrinsics.fx, b.stereo.right->intrinsics.fx);
    EXPECT_DOUBLE_EQ(a.stereo.right->distortion.k2, b.stereo.right->distortion.k2);
    EXPECT_EQ(a.stereo.right->model, b.stereo.right->model);
    EXPECT_DOUBLE_EQ(a.stereo.right->fisheye.k3, b.stereo.right->fisheye.k3);
    EXPECT_TRUE(a.stereo.T_c1_c2.matrix().isApprox(b.stereo.T_c1_c2.matrix(), 1e-14));
  }
  EXPECT_DOUBLE_EQ(a.rgbd.depth_map_factor, b.rgbd.depth_map_factor);
  EXPECT_EQ(a.orb.n_features, b.orb.n_features);
  EXPECT_DOUBLE_EQ(a.orb.scale_factor, b.orb.scale_factor);
  EXPECT_EQ(a.orb.n_levels, b.orb.n_levels);
  EXPECT_EQ(a.orb.ini_th_fast, b.orb.ini_th_fast);
  EXPECT_EQ(a.orb.min_th_fast, b.orb.min_th_fast);
  EXPECT_EQ(a.saliency.source, b.saliency.source);
  EXPECT_EQ(a.saliency.model_path, b.saliency.model_path);
  EXPECT_DOUBLE_EQ(a.saliency.weight_a, b.saliency.weight_a);
  EXPECT_DOUBLE_EQ(a.saliency.weight_b, b.saliency.weight_b);
  EXPECT_DOUBLE_EQ(a.saliency.map_ba_max_weight, b.saliency.map_ba_max_weight);
  EXPECT_EQ(a.saliency.map_ba_depth, b.saliency.map_ba_depth);
  EXPECT_DOUBLE_EQ(a.saliency.depth_a, b.saliency.depth_a);
  EXPECT_DOUBLE_EQ(a.saliency.depth_b, b.saliency.depth_b);
  EXPECT_EQ(a.saliency.depth_near, b.saliency.depth_near);
  EXPECT_DOUBLE_EQ(a.saliency.saturation, b.saliency.saturation);
  EXPECT_DOUBLE_EQ(a.saliency.keypoint_floor, b.saliency.keypoint_floor);
  EXPECT_DOUBLE_EQ(a.saliency.keypoint_max_dropped_share, b.saliency.keypoint_max_dropped_share);
  EXPECT_EQ(a.mapping.mono_min_parallax_deg, b.mapping.mono_min_parallax_deg);
  EXPECT_EQ(a.system.seed, b.system.seed);
  EXPECT_EQ(a.system.deterministic, b.system.deterministic);
  EXPECT_EQ(a.system.load_atlas, b.system.load_atlas);
  EXPECT_EQ(a.system.save_atlas, b.system.save_atlas);
  EXPECT_EQ(a.loop_closing.enabled, b.loop_closing.enabled);
  EXPECT_EQ(a.loop_closing.vocabulary_path, b.loop_closing.vocabulary_path);
  EXPECT_EQ(a.loop_closing.merge_maps, b.loop_closing.merge_maps);
}

TEST(SettingsTest, SaveLoadRoundTrip) {
  TempDir tmp;
  write_text_file(tmp.file("old.yaml"), kOldKeys);
  write_text_file(tmp.file("v1.yaml"), kV1Stereo);
  write_text_file(tmp.file("fisheye.yaml"), kV1Fisheye);
  for (const char* name : {"old.yaml", "v1.yaml", "fisheye.yaml"}) {
    SCOPED_TRACE(name);
    Settings original = load_settings(tmp.file(name));
    original.saliency.model_path = "/models/a \"quoted\" path.onnx";
    original.saliency.weight_a = 0.1 + 0.2;    // not exactly representable in short decimal
    original.system.seed = 12345678901234ull;  // beyond 32-bit
    original.camera.fps = 20.0;                // integral double
    original.mapping.mono_min_parallax_deg = 0.1 + 0.2;
    original.loop_closing.enabled = true;
    original.loop_closing.vocabulary_path = "/v/orb vocabulary.bin";
    original.loop_closing.merge_maps = false;
    if (std::string(name) == "fisheye.yaml")
      original.T_body_cam0 = SE3(SO3::exp(Vec3(0.1, -0.2, 0.3)), Vec3(0.01, 0.02, -0.03));
    const std::string saved = tmp.file(std::string("saved_") + name);
    save_settings(original, saved);
    const Settings loaded = load_settings(saved);
    EXPECT_EQ(loaded.path, saved);
    expect_same(original, loaded);
  }
}

TEST(SettingsTest, SaveToUnwritablePathIsAnError) {
  TempDir tmp;
  EXPECT_THROW(save_settings(Settings{}, tmp.file("no/such/dir/settings.yaml")), Error);
}

}  // namespace
}  // namespace sbaslam
