#pragma once
// Typed settings. The ORB-SLAM3 settings yaml (old keys and File.version "1.0" keys) is parsed
// once, through cv::FileStorage, into these structs and validated there; algorithms read fields,
// never string keys. Our own keys (Saliency.*, System.*) sit beside ORB-SLAM3's in the same file.

#include <cstdint>
#include <optional>
#include <string>

#include "sbaslam/core/lie.h"

namespace sbaslam {

struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
};

// Radial-tangential (OpenCV "plumb bob") distortion.
struct RadTanDistortion {
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;
  bool is_zero() const { return k1 == 0.0 && k2 == 0.0 && p1 == 0.0 && p2 == 0.0 && k3 == 0.0; }
};

// Kannala-Brandt fisheye distortion (ORB-SLAM3's "KannalaBrandt8", OpenCV's cv::fisheye, Kalibr's
// "equidistant"): a ray at angle theta to the optical axis lands at radius
// theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8) on the normalised plane.
struct KannalaBrandtDistortion {
  double k1 = 0.0, k2 = 0.0, k3 = 0.0, k4 = 0.0;
};

// ORB-SLAM3's Camera.type: "PinHole" (and "Rectified") or "KannalaBrandt8".
enum class CameraModel { kPinhole, kKannalaBrandt8 };

struct CameraSettings {
  PinholeIntrinsics intrinsics;
  CameraModel model = CameraModel::kPinhole;
  RadTanDistortion distortion;      // kPinhole
  KannalaBrandtDistortion fisheye;  // kKannalaBrandt8
  int width = 0;
  int height = 0;
  double fps = 0.0;
  bool rgb = true;  // Camera.RGB: colour order of the input images.
};

// One camera's precomputed rectification, as ORB-SLAM2's stereo files (and ORB-SLAM3's before
// v1.0) give it in LEFT.* / RIGHT.*: K and D (LEFT.K, LEFT.D, LEFT.width, LEFT.height) describe
// the raw camera, R rotates its rays into the rectified frame and P projects them there; ORB-SLAM's
// stereo_euroc example hands them to cv::initUndistortRectifyMap.
struct CameraRectification {
  CameraSettings raw;  // pinhole with radial-tangential distortion
  Mat3 R = Mat3::Identity();
  Mat34 P = Mat34::Zero();
};

struct PrecomputedRectification {
  CameraRectification left, right;
};

// A stereo rig. When the second camera is given with its own intrinsics and extrinsics
// (ORB-SLAM3 v1.0 "Camera2.*" + "Stereo.T_c1_c2", the same with "Tlr" in its older files, or
// EuRoC sensor.yaml), the rig is unrectified:
// `right` is set, `baseline` is |t_c1_c2| (rectification keeps it) and `bf` stays 0 until
// rectified_settings() (core/stereo_rectifier.h) replaces the intrinsics by the rectified ones.
// ORB-SLAM's RGB-D mode also uses bf (Camera.bf) for its virtual right coordinate, so an RGB-D
// file that gives Camera.bf has `enabled` set as well.
struct StereoSettings {
  bool enabled = false;   // the file gives a baseline (Camera.bf, Stereo.b or Camera2 + T_c1_c2)
  double baseline = 0.0;  // metres, after rectification
  double bf = 0.0;        // baseline times fx (ORB-SLAM's Camera.bf)
  double th_depth = 0.0;  // ORB-SLAM's ThDepth: close points are nearer than th_depth * baseline
  std::optional<CameraSettings> right;  // present when unrectified
  SE3 T_c1_c2;                          // pose of the right camera in the left camera's frame
  // LEFT.* / RIGHT.*: the raw pair is rectified with these; Camera.* and Camera.bf then describe
  // the rectified images (ORB-SLAM2's rule: Camera.fx ... must equal LEFT.P), checked on reading.
  std::optional<PrecomputedRectification> precomputed;

  bool needs_rectification() const { return right.has_value() || precomputed.has_value(); }
};

struct RgbdSettings {
  double depth_map_factor = 1.0;  // raw depth value / factor = metres
};

struct OrbSettings {
  int n_features = 1000;
  double scale_factor = 1.2;
  int n_levels = 8;
  int ini_th_fast = 20;
  int min_th_fast = 7;
};

// A user's monocular depth network in ONNX (Saliency.depth: "model"). Only relative depth
// matters: Algorithm 1 normalises by the maximum, so any global scale of D cancels.
struct DepthModelSettings {
  std::string path;     // Saliency.depth_model
  int width = 0;        // Saliency.depth_model_width: the network's input size
  int height = 0;       // Saliency.depth_model_height
  int channels = 3;     // Saliency.depth_model_channels: 1 (grey) or 3 (grey copied to RGB)
  bool inverse = true;  // Saliency.depth_model_output: "inverse_depth" (MonoDepth) or "depth"
};

struct SaliencySettings {
  // "model" (the shipped ONNX, Salient BA: the paper's method), "none" (uniform BA, ORB-SLAM3's)
  // or a folder of precomputed maps. Salient BA beats uniform BA on every ablation case; on
  // monocular `city-dynamic` by 0.38x, where the issue asks 0.5x (docs/RESULTS.md, "Session 48").
  // "none" is the baseline for ablations.
  std::string source = "model";
  std::string model_path;  // ONNX file; empty means the shipped model
  // w = a * S^2 + b, S in [0, 1]. a = 256, b = 1 from the sweep in docs/RESULTS.md (Salient BA).
  double weight_a = 256.0;
  double weight_b = 1.0;
  // Local and full BA rescale the weights so that the largest, a + b, becomes this; motion-only
  // BA uses them as they are. The ratios stay a S^2 + b; only where the Huber kernel's corner
  // falls changes: at the full 257 it is 0.15 whitened px, which makes the cost about the sum of
  // |e|. That robustness is where motion-only BA gains (moving cars; EuRoC needs it), but a map
  // point of local BA has two or three observations, and an L1 fit of so few likely moves little
  // from its start: `room` lost 10 % with it. 16 (the corner at 0.6 px) from the 10-run sets in
  // docs/RESULTS.md ("Session 25"): `room` 1.10x -> 0.89x, monocular `city-dynamic` 0.47x ->
  // 0.52x. 0 keeps the same weights in every BA (the paper's wording).
  double map_ba_max_weight = 16.0;
  // The factor local and full BA multiply each weight by (1 when map_ba_max_weight is 0).
  double map_ba_weight_scale() const {
    return map_ba_max_weight > 0.0 ? map_ba_max_weight / (weight_a + weight_b) : 1.0;
  }
  // Where local and full BA take the D of Algorithm 1 from. "frame": the weight stored with each
  // keypoint when its frame was built, from that frame's depth map (for a monocular frame, the
  // map points tracked in the last frame, densified on a coarse grid; motion-only BA always uses
  // it). "point": each observation's weight is recomputed whenever a BA is built, from the
  // keypoint's S_init and its map point's own depth in the keyframe at that moment
  // (saliency::point_depth_weight), so the weight follows the point as BA moves it and a keypoint
  // that had no depth sample when its frame was built still gets its own. "auto": "point" on
  // monocular rigs, "frame" on stereo and RGB-D. Monocular `city-dynamic`: 0.56x -> 0.38x
  // (0.41x over 20 runs; docs/RESULTS.md, "Session 48"). Needs Saliency.depth other than "none".
  std::string map_ba_depth = "auto";
  // map_ba_depth resolved for a rig: true where local and full BA use each point's own depth.
  bool map_ba_point_depth(bool stereo_or_rgbd) const {
    if (depth_source == "none") return false;
    return map_ba_depth == "point" || (map_ba_depth == "auto" && !stereo_or_rgbd);
  }
  double depth_a = 1.0;  // S_final = depth_a * S_init / D + depth_b, then normalised to 0..255
  double depth_b = 0.0;
  // Metres below which every depth counts as this one, D = max(D, depth_near): Algorithm 1 then
  // favours near points only over points beyond it. Unset ("auto"): the rig's close-point
  // threshold, ThDepth times the baseline, for stereo and RGB-D; for monocular frames, whose map
  // has no metric scale, the median depth of the frame's depth samples (the map points tracked
  // into it, or its velodyne scan; 0 with a depth network). 0: the paper's plain 1 / D.
  std::optional<double> depth_near;
  // S_init = min(1, S_init / saturation) before the depth correction: 1 keeps the map as it is
  // (the paper); below 1 the map acts as a soft mask of static structure rather than a ranking
  // within it. 0.02 from the sweep in docs/RESULTS.md ("Session 19").
  double saturation = 0.02;
  // Where D comes from: "auto" (a stereo frame: its stereo matches, densified; a monocular frame:
  // the map points tracked in the last frame, predicted into it and densified), "model" (a
  // user-supplied ONNX depth network, the paper's MonoDepth way; see DepthModelSettings),
  // "velodyne" (KITTI scans next to the images, saliency/velodyne_depth.h) or "none" (S_init is
  // used as it is). "stereo", the name before monocular frames had a depth,
  // means "auto".
  std::string depth_source = "auto";
  DepthModelSettings depth_model;
  // Saliency-guided extraction, beyond the paper (Salient DSO selects its points by saliency):
  // keypoints where the saturated map S_init is below this, in [0, 1], are dropped before
  // tracking, but never more than keypoint_max_dropped_share of a frame's. 0: every keypoint is
  // kept and only the BA weights use the map (the paper). Floors of 0.5 and 1 left monocular
  // `city-dynamic` where the weights alone put it (docs/RESULTS.md, "Session 40").
  double keypoint_floor = 0.0;
  double keypoint_max_dropped_share = 0.5;
};

struct MappingSettings {
  // Monocular rigs: the least angle between two keyframes' rays for a new point to be triangulated
  // from them (Mapping.mono_min_parallax_deg); unset, ORB-SLAM's gate (cos 0.9998, 1.15 degrees).
  // 2.5 degrees cuts uniform BA's monocular scale drift on the city renders, but not Salient BA's
  // error, the default's (docs/RESULTS.md, "Session 27"). Stereo rigs always keep ORB-SLAM's gate.
  std::optional<double> mono_min_parallax_deg;
};

// ORB-SLAM3's `loopClosing` key (0 or 1) and the vocabulary of place recognition.
struct LoopClosingSettings {
  // ORB-SLAM3's default: on unless the file says `loopClosing: 0` (or `run --loop-closing off`).
  // Results before session 30 were measured with it off (docs/RESULTS.md).
  bool enabled = true;
  std::string vocabulary_path;  // LoopClosing.vocabulary; empty: the shipped one
  // LoopClosing.merge_maps: a loop to a map started before a loss merges the two (ORB-SLAM3's
  // Atlas always merges); 0 leaves such loops alone.
  bool merge_maps = true;
};

struct SystemSettings {
  std::uint64_t seed = 0;
  bool deterministic = false;
  // ORB-SLAM3's System.LoadAtlasFromFile and System.SaveAtlasToFile: a file name to which, as
  // there, ".osa" is appended (relative to the working folder). The file is sba-slam's own map
  // format (map/map_file.h), not ORB-SLAM3's. `run --load-map` / `--save-map` override them.
  std::string load_atlas;
  std::string save_atlas;
};

// ORB-SLAM3's Camera.newWidth / Camera.newHeight: the size the images are resized to before
// tracking (0: that side keeps Camera.width / Camera.height).
struct ImageResize {
  int width = 0;
  int height = 0;
};

struct Settings {
  std::string path;  // file the settings came from, for messages
  CameraSettings camera;
  std::optional<ImageResize> resize;
  StereoSettings stereo;
  RgbdSettings rgbd;
  OrbSettings orb;
  SaliencySettings saliency;
  MappingSettings mapping;
  LoopClosingSettings loop_closing;
  SystemSettings system;
  // IMU.T_b_c1 (Tbc in older files): cam0's pose in the body (IMU) frame, as ORB-SLAM3's inertial
  // files give it. SLAM does not use it; it places a body-frame ground truth on the camera.
  std::optional<SE3> T_body_cam0;
};

// Reads an ORB-SLAM3 settings file, old keys (Camera.fx, Camera.bf, ThDepth, DepthMapFactor;
// Camera2.* and Tlr for an unrectified pair, or ORB-SLAM2's LEFT.* / RIGHT.* rectification) or
// File.version "1.0" keys (Camera1.fx, Camera2.*, Stereo.b, Stereo.T_c1_c2, RGBD.*), plus our
// Saliency.*, Mapping.* and System.* keys, and IMU.T_b_c1 / Tbc. Keys we do not use (Viewer.*,
// the other IMU.* keys, ...) are ignored.
// Throws sbaslam::Error naming the key and the file for every missing or invalid value.
Settings load_settings(const std::string& path);

// Writes the settings in the File.version "1.0" layout that ORB-SLAM3 reads, with our keys beside
// them; load_settings() of the written file gives the same settings back (except `path`).
void save_settings(const Settings& settings, const std::string& path);

}  // namespace sbaslam
