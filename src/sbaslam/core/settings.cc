#include "sbaslam/core/settings.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <set>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam {
namespace {

// Typed, validated access to the keys of one open settings file. Every failure names the key and
// the file.
class KeyReader {
 public:
  KeyReader(const cv::FileStorage& fs, std::string path) : fs_(fs), path_(std::move(path)) {}

  const std::string& path() const { return path_; }
  bool has(const std::string& key) const { return !fs_[key].empty() && !fs_[key].isNone(); }

  std::optional<double> optional_real(const std::string& key) const {
    if (!has(key)) return std::nullopt;
    const cv::FileNode node = fs_[key];
    if (!node.isReal() && !node.isInt()) fail("{}: '{}' must be a number", path_, key);
    const double value = static_cast<double>(node);
    if (!std::isfinite(value)) fail("{}: '{}' is not finite ({})", path_, key, value);
    return value;
  }
  double real(const std::string& key) const {
    const auto value = optional_real(key);
    if (!value) fail("{}: missing key '{}'", path_, key);
    return *value;
  }
  double positive_real(const std::string& key) const {
    const double value = real(key);
    if (value <= 0.0) fail("{}: '{}' must be positive, got {}", path_, key, value);
    return value;
  }
  double real_or(const std::string& key, double fallback) const {
    return optional_real(key).value_or(fallback);
  }

  std::optional<long long> optional_integer(const std::string& key) const {
    const auto value = optional_real(key);
    if (!value) return std::nullopt;
    if (std::floor(*value) != *value || std::abs(*value) > 9.0e15)
      fail("{}: '{}' must be an integer, got {}", path_, key, *value);
    return static_cast<long long>(*value);
  }
  int integer_at_least(const std::string& key, int minimum) const {
    const auto value = optional_integer(key);
    if (!value) fail("{}: missing key '{}'", path_, key);
    if (*value < minimum || *value > std::numeric_limits<int>::max())
      fail("{}: '{}' must be at least {}, got {}", path_, key, minimum, *value);
    return static_cast<int>(*value);
  }

  std::optional<std::string> optional_string(const std::string& key) const {
    if (!has(key)) return std::nullopt;
    const cv::FileNode node = fs_[key];
    if (node.isString()) return node.string();
    if (node.isReal() || node.isInt()) return fmt::format("{}", static_cast<double>(node));
    fail("{}: '{}' must be a string", path_, key);
  }

  // Accepts 0/1 (as ORB-SLAM3 writes Camera.RGB) and the strings true/false.
  bool boolean_or(const std::string& key, bool fallback) const {
    if (!has(key)) return fallback;
    const cv::FileNode node = fs_[key];
    if (node.isString()) {
      const std::string text = node.string();
      if (text == "true" || text == "True" || text == "1") return true;
      if (text == "false" || text == "False" || text == "0") return false;
      fail("{}: '{}' must be 0, 1, true or false, got '{}'", path_, key, text);
    }
    const auto value = optional_integer(key);
    if (*value != 0 && *value != 1) fail("{}: '{}' must be 0 or 1, got {}", path_, key, *value);
    return *value == 1;
  }

  cv::FileNode node(const std::string& key) const { return fs_[key]; }

 private:
  const cv::FileStorage& fs_;
  std::string path_;
};

// Reads "<prefix>.fx" ... (prefix "Camera" in old files, "Camera1"/"Camera2" in v1.0 files) for
// camera.model: k1, k2, p1, p2, k3 for a pinhole camera, optional and zero by default; k1 ... k4
// for a Kannala-Brandt one, required as in ORB-SLAM3.
void read_camera(const KeyReader& keys, const std::string& prefix, CameraSettings& camera) {
  camera.intrinsics.fx = keys.positive_real(prefix + ".fx");
  camera.intrinsics.fy = keys.positive_real(prefix + ".fy");
  camera.intrinsics.cx = keys.real(prefix + ".cx");
  camera.intrinsics.cy = keys.real(prefix + ".cy");
  if (camera.model == CameraModel::kKannalaBrandt8) {
    camera.fisheye.k1 = keys.real(prefix + ".k1");
    camera.fisheye.k2 = keys.real(prefix + ".k2");
    camera.fisheye.k3 = keys.real(prefix + ".k3");
    camera.fisheye.k4 = keys.real(prefix + ".k4");
    return;
  }
  camera.distortion.k1 = keys.real_or(prefix + ".k1", 0.0);
  camera.distortion.k2 = keys.real_or(prefix + ".k2", 0.0);
  camera.distortion.p1 = keys.real_or(prefix + ".p1", 0.0);
  camera.distortion.p2 = keys.real_or(prefix + ".p2", 0.0);
  camera.distortion.k3 = keys.real_or(prefix + ".k3", 0.0);
}

// Keys shared by both layouts: image size, rate and colour order.
void read_image_keys(const KeyReader& keys, CameraSettings& camera) {
  camera.width = keys.integer_at_least("Camera.width", 1);
  camera.height = keys.integer_at_least("Camera.height", 1);
  // ORB-SLAM3 falls back to 30 fps when the rate is absent.
  camera.fps = keys.has("Camera.fps") ? keys.positive_real("Camera.fps") : 30.0;
  camera.rgb = keys.boolean_or("Camera.RGB", true);
}

std::optional<ImageResize> read_resize(const KeyReader& keys) {
  if (!keys.has("Camera.newWidth") && !keys.has("Camera.newHeight")) return std::nullopt;
  ImageResize resize;
  if (keys.has("Camera.newWidth")) resize.width = keys.integer_at_least("Camera.newWidth", 1);
  if (keys.has("Camera.newHeight")) resize.height = keys.integer_at_least("Camera.newHeight", 1);
  return resize;
}

CameraModel read_camera_type(const KeyReader& keys, bool required) {
  const auto type = keys.optional_string("Camera.type");
  if (!type) {
    if (required) fail("{}: missing key 'Camera.type'", keys.path());
    return CameraModel::kPinhole;
  }
  if (*type == "PinHole" || *type == "Rectified") return CameraModel::kPinhole;
  if (*type == "KannalaBrandt8") return CameraModel::kKannalaBrandt8;
  fail("{}: 'Camera.type' is '{}'; known: \"PinHole\", \"Rectified\", \"KannalaBrandt8\"",
       keys.path(), *type);
}

// An !!opencv-matrix of doubles, every value finite; `rows` x `cols` unless cols is 0.
cv::Mat read_matrix(const KeyReader& keys, const std::string& key, int rows, int cols) {
  cv::Mat matrix;
  try {
    keys.node(key) >> matrix;
  } catch (const cv::Exception&) {
    fail("{}: '{}' must be an !!opencv-matrix", keys.path(), key);
  }
  if (matrix.empty())
    fail("{}: missing or invalid '{}' (expected an !!opencv-matrix)", keys.path(), key);
  if (matrix.channels() != 1 || (cols > 0 && (matrix.rows != rows || matrix.cols != cols)))
    fail("{}: '{}' must be {}x{}, got {}x{}", keys.path(), key, rows, cols, matrix.rows,
         matrix.cols);
  matrix.convertTo(matrix, CV_64F);
  for (int r = 0; r < matrix.rows; ++r)
    for (int c = 0; c < matrix.cols; ++c)
      if (!std::isfinite(matrix.at<double>(r, c)))
        fail("{}: '{}' holds a non-finite value", keys.path(), key);
  return matrix;
}

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> read_fixed_matrix(const KeyReader& keys, const std::string& key) {
  const cv::Mat matrix = read_matrix(keys, key, Rows, Cols);
  Eigen::Matrix<double, Rows, Cols> out;
  for (int r = 0; r < Rows; ++r)
    for (int c = 0; c < Cols; ++c) out(r, c) = matrix.at<double>(r, c);
  return out;
}

void check_rotation(const KeyReader& keys, const std::string& key, const Mat3& R) {
  // The file usually stores single precision (dt: f), hence the loose tolerance.
  if ((R * R.transpose() - Mat3::Identity()).norm() > 1e-4 || R.determinant() < 0.0)
    fail("{}: '{}' does not hold a rotation", keys.path(), key);
}

// A rigid transform as a 4x4 (or, for the old layout's "Tlr", 3x4) !!opencv-matrix.
SE3 read_pose_matrix(const KeyReader& keys, const std::string& key, int rows) {
  Mat4 T = Mat4::Identity();
  if (rows == 3)
    T.topRows<3>() = read_fixed_matrix<3, 4>(keys, key);
  else
    T = read_fixed_matrix<4, 4>(keys, key);
  check_rotation(keys, key, T.topLeftCorner<3, 3>());
  return SE3::from_matrix(T);
}

// Camera2.* and the pose of the second camera in the first of an unrectified rig: v1.0's
// "Stereo.T_c1_c2" (4x4), or the old layout's "Tlr" (3x4), which ORB-SLAM3 reads as the same.
void read_second_camera(const KeyReader& keys, const std::string& pose_key, int pose_rows,
                        Settings& s) {
  CameraSettings right = s.camera;
  read_camera(keys, "Camera2", right);
  s.stereo.T_c1_c2 = read_pose_matrix(keys, pose_key, pose_rows);
  s.stereo.baseline = s.stereo.T_c1_c2.translation().norm();
  if (!(s.stereo.baseline > 0.0)) fail("{}: '{}' has a zero baseline", keys.path(), pose_key);
  s.stereo.right = right;
  s.stereo.enabled = true;
  s.stereo.bf = 0.0;  // until rectified (StereoSettings); old files give Camera.bf too
}

// LEFT.K, LEFT.D, LEFT.R, LEFT.P, LEFT.width, LEFT.height (side "LEFT" or "RIGHT").
CameraRectification read_rectification(const KeyReader& keys, const std::string& side,
                                       const CameraSettings& rectified) {
  CameraRectification r;
  r.raw = rectified;  // rate and colour order
  r.raw.model = CameraModel::kPinhole;
  r.raw.width = keys.integer_at_least(side + ".width", 1);
  r.raw.height = keys.integer_at_least(side + ".height", 1);
  const Mat3 K = read_fixed_matrix<3, 3>(keys, side + ".K");
  if (!(K(0, 0) > 0.0 && K(1, 1) > 0.0) || K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 ||
      K(2, 2) != 1.0 || K(0, 1) != 0.0)
    fail("{}: '{}.K' is not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]", keys.path(), side);
  r.raw.intrinsics = {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
  const cv::Mat D = read_matrix(keys, side + ".D", 0, 0);
  if ((D.rows != 1 && D.cols != 1) || (D.total() != 4 && D.total() != 5))
    fail("{}: '{}.D' must hold 4 or 5 coefficients (k1 k2 p1 p2 [k3]), got {}x{}", keys.path(),
         side, D.rows, D.cols);
  const auto d = [&D](int i) { return i < static_cast<int>(D.total()) ? D.at<double>(i) : 0.0; };
  r.raw.distortion = {d(0), d(1), d(2), d(3), d(4)};
  r.R = read_fixed_matrix<3, 3>(keys, side + ".R");
  check_rotation(keys, side + ".R", r.R);
  r.P = read_fixed_matrix<3, 4>(keys, side + ".P");
  if (!(r.P(0, 0) > 0.0 && r.P(1, 1) > 0.0) || r.P.row(2) != Eigen::RowVector4d(0, 0, 1, 0))
    fail("{}: '{}.P' is not a rectified projection [fx 0 cx tx; 0 fy cy 0; 0 0 1 0]", keys.path(),
         side);
  return r;
}

// The rectified images' camera as a projection gives it, against what Camera.* says of them.
void check_rectified_camera(const KeyReader& keys, const std::string& key, const Mat34& P,
                            const PinholeIntrinsics& k) {
  // Files print these to varying digits; 0.05 px is far below what would mislead tracking.
  constexpr double kTolerancePx = 0.05;
  const double p[] = {P(0, 0), P(1, 1), P(0, 2), P(1, 2)};
  const double c[] = {k.fx, k.fy, k.cx, k.cy};
  for (int i = 0; i < 4; ++i)
    if (std::abs(p[i] - c[i]) > kTolerancePx)
      fail(
          "{}: '{}' gives the rectified camera fx {} fy {} cx {} cy {}, but Camera.* says fx {} "
          "fy {} cx {} cy {}; they must be the same",
          keys.path(), key, p[0], p[1], p[2], p[3], c[0], c[1], c[2], c[3]);
}

// ORB-SLAM2's precomputed rectification of the pair (LEFT.* and RIGHT.*), read when any of its
// keys is present; Camera.* and Camera.bf (or Stereo.b) must describe its rectified images.
void read_precomputed_rectification(const KeyReader& keys, Settings& s) {
  bool present = false;
  for (const char* side : {"LEFT", "RIGHT"})
    for (const char* field : {".K", ".D", ".R", ".P", ".width", ".height"})
      present = present || keys.has(std::string(side) + field);
  if (!present) return;
  if (s.stereo.right)
    fail("{}: both LEFT.* / RIGHT.* (a rectification) and Camera2.* describe the stereo pair",
         keys.path());
  if (s.camera.model != CameraModel::kPinhole || !s.camera.distortion.is_zero())
    fail(
        "{}: with LEFT.* / RIGHT.*, Camera.* describes the rectified images: a pinhole camera "
        "without distortion",
        keys.path());
  if (!s.stereo.enabled)
    fail("{}: LEFT.* / RIGHT.* need the rectified pair's Camera.bf", keys.path());
  PrecomputedRectification p{read_rectification(keys, "LEFT", s.camera),
                             read_rectification(keys, "RIGHT", s.camera)};
  check_rectified_camera(keys, "LEFT.P", p.left.P, s.camera.intrinsics);
  check_rectified_camera(keys, "RIGHT.P", p.right.P, s.camera.intrinsics);
  if (p.left.P(0, 3) != 0.0 || p.left.P(1, 3) != 0.0 || p.right.P(1, 3) != 0.0)
    fail("{}: 'LEFT.P' must have no translation and 'RIGHT.P' only along x", keys.path());
  const double bf = -p.right.P(0, 3);
  if (std::abs(bf - s.stereo.bf) > 1e-3 * s.stereo.bf)
    fail("{}: 'RIGHT.P' gives baseline times fx {}, but Camera.bf is {}", keys.path(), bf,
         s.stereo.bf);
  for (const CameraRectification* r : {&p.left, &p.right})
    if (r->raw.width != s.camera.width || r->raw.height != s.camera.height)
      fail("{}: LEFT.* / RIGHT.* are for {}x{} images, Camera.width/height say {}x{}", keys.path(),
           r->raw.width, r->raw.height, s.camera.width, s.camera.height);
  s.stereo.precomputed = std::move(p);
}

void read_old_layout(const KeyReader& keys, Settings& s) {
  s.camera.model = read_camera_type(keys, false);
  read_camera(keys, "Camera", s.camera);
  read_image_keys(keys, s.camera);
  if (keys.has("Camera.bf")) {
    s.stereo.enabled = true;
    s.stereo.bf = keys.positive_real("Camera.bf");
    s.stereo.baseline = s.stereo.bf / s.camera.intrinsics.fx;
  }
  // ORB-SLAM3's files before v1.0 describe an unrectified (fisheye) pair this way (TUM-VI).
  if (keys.has("Camera2.fx")) read_second_camera(keys, "Tlr", 3, s);
  if (keys.has("ThDepth") || s.stereo.enabled) s.stereo.th_depth = keys.positive_real("ThDepth");
  read_precomputed_rectification(keys, s);
  if (keys.has("DepthMapFactor")) s.rgbd.depth_map_factor = keys.positive_real("DepthMapFactor");
}

void read_v1_layout(const KeyReader& keys, Settings& s) {
  s.camera.model = read_camera_type(keys, true);
  read_camera(keys, "Camera1", s.camera);
  read_image_keys(keys, s.camera);
  if (keys.has("Camera2.fx")) {
    read_second_camera(keys, "Stereo.T_c1_c2", 4, s);
  } else if (keys.has("Stereo.b")) {
    s.stereo.baseline = keys.positive_real("Stereo.b");
    s.stereo.bf = s.stereo.baseline * s.camera.intrinsics.fx;
    s.stereo.enabled = true;
  }
  if (keys.has("Stereo.ThDepth") || s.stereo.enabled)
    s.stereo.th_depth = keys.positive_real("Stereo.ThDepth");
  read_precomputed_rectification(keys, s);
  if (keys.has("RGBD.DepthMapFactor"))
    s.rgbd.depth_map_factor = keys.positive_real("RGBD.DepthMapFactor");
}

void read_orb(const KeyReader& keys, OrbSettings& orb) {
  orb.n_features = keys.integer_at_least("ORBextractor.nFeatures", 1);
  orb.scale_factor = keys.real("ORBextractor.scaleFactor");
  if (orb.scale_factor <= 1.0)
    fail("{}: 'ORBextractor.scaleFactor' must be greater than 1, got {}", keys.path(),
         orb.scale_factor);
  orb.n_levels = keys.integer_at_least("ORBextractor.nLevels", 1);
  orb.ini_th_fast = keys.integer_at_least("ORBextractor.iniThFAST", 1);
  orb.min_th_fast = keys.integer_at_least("ORBextractor.minThFAST", 1);
  if (orb.min_th_fast > orb.ini_th_fast)
    fail("{}: 'ORBextractor.minThFAST' ({}) exceeds 'ORBextractor.iniThFAST' ({})", keys.path(),
         orb.min_th_fast, orb.ini_th_fast);
}

void read_depth_model(const KeyReader& keys, DepthModelSettings& model) {
  model.path = keys.optional_string("Saliency.depth_model").value_or("");
  if (model.path.empty())
    fail("{}: 'Saliency.depth' is \"model\" but 'Saliency.depth_model' (an ONNX file) is not set",
         keys.path());
  model.width = keys.integer_at_least("Saliency.depth_model_width", 1);
  model.height = keys.integer_at_least("Saliency.depth_model_height", 1);
  const auto channels = keys.optional_integer("Saliency.depth_model_channels");
  if (channels) model.channels = static_cast<int>(*channels);
  if (model.channels != 1 && model.channels != 3)
    fail("{}: 'Saliency.depth_model_channels' must be 1 or 3, got {}", keys.path(), *channels);
  const std::string output =
      keys.optional_string("Saliency.depth_model_output").value_or("inverse_depth");
  if (output != "inverse_depth" && output != "depth")
    fail("{}: 'Saliency.depth_model_output' must be \"inverse_depth\" or \"depth\" (got \"{}\")",
         keys.path(), output);
  model.inverse = output == "inverse_depth";
}

// "auto" (or absent) leaves it unset: the rig decides (SaliencySettings::depth_near).
void read_depth_near(const KeyReader& keys, SaliencySettings& sal) {
  const std::string key = "Saliency.depth_near";
  if (!keys.has(key)) return;
  if (keys.node(key).isString()) {
    const std::string text = keys.node(key).string();
    if (text != "auto")
      fail("{}: '{}' must be \"auto\" or metres >= 0, got '{}'", keys.path(), key, text);
    sal.depth_near.reset();
    return;
  }
  const double metres = keys.real_or(key, 0.0);
  if (metres < 0.0)
    fail("{}: '{}' must be \"auto\" or metres >= 0, got {}", keys.path(), key, metres);
  sal.depth_near = metres;
}

void read_mapping(const KeyReader& keys, MappingSettings& mapping) {
  const std::string key = "Mapping.mono_min_parallax_deg";
  mapping.mono_min_parallax_deg = keys.optional_real(key);
  const auto& value = mapping.mono_min_parallax_deg;
  if (value && !(*value > 0.0 && *value < 90.0))
    fail("{}: '{}' must be in (0, 90) degrees, got {}", keys.path(), key, *value);
}

void read_keypoint_selection(const KeyReader& keys, SaliencySettings& sal) {
  sal.keypoint_floor = keys.real_or("Saliency.keypoint_floor", sal.keypoint_floor);
  if (!(sal.keypoint_floor >= 0.0 && sal.keypoint_floor <= 1.0))
    fail("{}: 'Saliency.keypoint_floor' must be in [0, 1] (0: keep every keypoint), got {}",
         keys.path(), sal.keypoint_floor);
  sal.keypoint_max_dropped_share =
      keys.real_or("Saliency.keypoint_max_dropped_share", sal.keypoint_max_dropped_share);
  if (!(sal.keypoint_max_dropped_share >= 0.0 && sal.keypoint_max_dropped_share < 1.0))
    fail("{}: 'Saliency.keypoint_max_dropped_share' must be in [0, 1), got {}", keys.path(),
         sal.keypoint_max_dropped_share);
}

void read_saliency(const KeyReader& keys, SaliencySettings& sal) {
  sal.source = keys.optional_string("Saliency.source").value_or(sal.source);
  if (sal.source.empty()) fail("{}: 'Saliency.source' is empty", keys.path());
  sal.model_path = keys.optional_string("Saliency.model").value_or(sal.model_path);
  sal.weight_a = keys.real_or("Saliency.a", sal.weight_a);
  sal.weight_b = keys.real_or("Saliency.b", sal.weight_b);
  // w = a S^2 + b over S in [0, 1] takes its extremes at b and a + b; BA needs w > 0.
  if (sal.weight_b <= 0.0 || sal.weight_a + sal.weight_b <= 0.0)
    fail(
        "{}: 'Saliency.a' ({}) and 'Saliency.b' ({}) give a non-positive weight for some "
        "saliency in [0, 1]",
        keys.path(), sal.weight_a, sal.weight_b);
  sal.map_ba_max_weight = keys.real_or("Saliency.map_ba_max_weight", sal.map_ba_max_weight);
  if (!(sal.map_ba_max_weight >= 0.0))
    fail("{}: 'Saliency.map_ba_max_weight' must be >= 0 (0: the weights as they are), got {}",
         keys.path(), sal.map_ba_max_weight);
  sal.map_ba_depth = keys.optional_string("Saliency.map_ba_depth").value_or(sal.map_ba_depth);
  if (sal.map_ba_depth != "auto" && sal.map_ba_depth != "frame" && sal.map_ba_depth != "point")
    fail("{}: 'Saliency.map_ba_depth' must be \"auto\", \"frame\" or \"point\" (got \"{}\")",
         keys.path(), sal.map_ba_depth);
  sal.depth_a = keys.real_or("Saliency.depth_a", sal.depth_a);
  sal.depth_b = keys.real_or("Saliency.depth_b", sal.depth_b);
  read_depth_near(keys, sal);
  sal.saturation = keys.real_or("Saliency.saturation", sal.saturation);
  if (!(sal.saturation > 0.0 && sal.saturation <= 1.0))
    fail("{}: 'Saliency.saturation' must be in (0, 1], got {}", keys.path(), sal.saturation);
  sal.depth_source = keys.optional_string("Saliency.depth").value_or(sal.depth_source);
  if (sal.depth_source == "stereo") sal.depth_source = "auto";
  if (sal.depth_source != "auto" && sal.depth_source != "model" && sal.depth_source != "none" &&
      sal.depth_source != "velodyne")
    fail("{}: 'Saliency.depth' must be \"auto\", \"model\", \"velodyne\" or \"none\" (got \"{}\")",
         keys.path(), sal.depth_source);
  if (sal.depth_source == "model") read_depth_model(keys, sal.depth_model);
  read_keypoint_selection(keys, sal);
}

// Seeds above int32 are written as quoted decimal strings because YAML integers in
// cv::FileStorage are 32-bit.
std::uint64_t read_seed(const KeyReader& keys, std::uint64_t fallback) {
  const std::string key = "System.seed";
  if (!keys.has(key)) return fallback;
  if (keys.node(key).isString()) {
    const std::string text = keys.node(key).string();
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
        text.size() > 20)
      fail("{}: '{}' must be a non-negative integer, got '{}'", keys.path(), key, text);
    try {
      return std::stoull(text);
    } catch (const std::exception&) {
      fail("{}: '{}' is out of range ('{}')", keys.path(), key, text);
    }
  }
  const auto value = keys.optional_integer(key);
  if (*value < 0) fail("{}: '{}' must be a non-negative integer, got {}", keys.path(), key, *value);
  return static_cast<std::uint64_t>(*value);
}

bool is_v1_layout(const KeyReader& keys) {
  const auto version = keys.optional_string("File.version");
  if (!version) return false;
  if (*version != "1.0" && *version != "1")
    fail("{}: 'File.version' is '{}'; only \"1.0\" is supported", keys.path(), *version);
  return true;
}

// Doubles keep a decimal point (ORB-SLAM3 rejects integers where it expects reals) and enough
// digits to read back the same value.
std::string real_text(double value) {
  std::string text = fmt::format("{:.17g}", value);
  if (text.find_first_of(".en") == std::string::npos) text += ".0";
  return text;
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void write_camera(std::ostream& out, const std::string& prefix, const CameraSettings& camera) {
  const PinholeIntrinsics& k = camera.intrinsics;
  out << prefix << ".fx: " << real_text(k.fx) << "\n"
      << prefix << ".fy: " << real_text(k.fy) << "\n"
      << prefix << ".cx: " << real_text(k.cx) << "\n"
      << prefix << ".cy: " << real_text(k.cy) << "\n\n";
  if (camera.model == CameraModel::kKannalaBrandt8) {
    const KannalaBrandtDistortion& f = camera.fisheye;
    out << prefix << ".k1: " << real_text(f.k1) << "\n"
        << prefix << ".k2: " << real_text(f.k2) << "\n"
        << prefix << ".k3: " << real_text(f.k3) << "\n"
        << prefix << ".k4: " << real_text(f.k4) << "\n\n";
    return;
  }
  const RadTanDistortion& d = camera.distortion;
  out << prefix << ".k1: " << real_text(d.k1) << "\n"
      << prefix << ".k2: " << real_text(d.k2) << "\n"
      << prefix << ".p1: " << real_text(d.p1) << "\n"
      << prefix << ".p2: " << real_text(d.p2) << "\n"
      << prefix << ".k3: " << real_text(d.k3) << "\n\n";
}

void write_matrix(std::ostream& out, const std::string& key, const double* values, int rows,
                  int cols) {
  out << key << ": !!opencv-matrix\n  rows: " << rows << "\n  cols: " << cols
      << "\n  dt: d\n  data: [";
  for (int i = 0; i < rows * cols; ++i) out << (i ? ", " : "") << real_text(values[i]);
  out << "]\n";
}

void write_pose_matrix(std::ostream& out, const std::string& key, const SE3& pose) {
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = pose.matrix();
  write_matrix(out, key, T.data(), 4, 4);
}

void write_rectification(std::ostream& out, const std::string& side, const CameraRectification& r) {
  const PinholeIntrinsics& k = r.raw.intrinsics;
  const RadTanDistortion& d = r.raw.distortion;
  const double K[] = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  const double D[] = {d.k1, d.k2, d.p1, d.p2, d.k3};
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = r.R;
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> P = r.P;
  out << side << ".width: " << r.raw.width << "\n" << side << ".height: " << r.raw.height << "\n";
  write_matrix(out, side + ".K", K, 3, 3);
  write_matrix(out, side + ".D", D, 1, 5);
  write_matrix(out, side + ".R", R.data(), 3, 3);
  write_matrix(out, side + ".P", P.data(), 3, 4);
}

void write_stereo(std::ostream& out, const Settings& s) {
  if (s.stereo.precomputed) {
    write_rectification(out, "LEFT", s.stereo.precomputed->left);
    write_rectification(out, "RIGHT", s.stereo.precomputed->right);
  }
  if (s.stereo.right) {
    write_camera(out, "Camera2", *s.stereo.right);
    write_pose_matrix(out, "Stereo.T_c1_c2", s.stereo.T_c1_c2);
  } else if (s.stereo.enabled) {
    out << "Stereo.b: " << real_text(s.stereo.baseline) << "\n";
  }
  if (s.stereo.th_depth > 0.0 || s.stereo.enabled)
    out << "Stereo.ThDepth: " << real_text(s.stereo.th_depth) << "\n";
  out << "\nRGBD.DepthMapFactor: " << real_text(s.rgbd.depth_map_factor) << "\n\n";
  if (s.T_body_cam0) {
    write_pose_matrix(out, "IMU.T_b_c1", *s.T_body_cam0);
    out << "\n";
  }
}

void write_ours(std::ostream& out, const Settings& s) {
  const SaliencySettings& sal = s.saliency;
  out << "# sba-slam keys\n"
      << "Saliency.source: " << quoted(sal.source) << "\n"
      << "Saliency.model: " << quoted(sal.model_path) << "\n"
      << "Saliency.a: " << real_text(sal.weight_a) << "\n"
      << "Saliency.b: " << real_text(sal.weight_b) << "\n"
      << "Saliency.map_ba_max_weight: " << real_text(sal.map_ba_max_weight) << "\n"
      << "Saliency.map_ba_depth: " << quoted(sal.map_ba_depth) << "\n"
      << "Saliency.depth_a: " << real_text(sal.depth_a) << "\n"
      << "Saliency.depth_b: " << real_text(sal.depth_b) << "\n"
      << "Saliency.depth_near: " << (sal.depth_near ? real_text(*sal.depth_near) : quoted("auto"))
      << "\n"
      << "Saliency.saturation: " << real_text(sal.saturation) << "\n"
      << "Saliency.depth: " << quoted(sal.depth_source) << "\n"
      << "Saliency.keypoint_floor: " << real_text(sal.keypoint_floor) << "\n"
      << "Saliency.keypoint_max_dropped_share: " << real_text(sal.keypoint_max_dropped_share)
      << "\n";
  if (sal.depth_source == "model")
    out << "Saliency.depth_model: " << quoted(sal.depth_model.path) << "\n"
        << "Saliency.depth_model_width: " << sal.depth_model.width << "\n"
        << "Saliency.depth_model_height: " << sal.depth_model.height << "\n"
        << "Saliency.depth_model_channels: " << sal.depth_model.channels << "\n"
        << "Saliency.depth_model_output: "
        << quoted(sal.depth_model.inverse ? "inverse_depth" : "depth") << "\n";
  out << "\n";
  if (s.mapping.mono_min_parallax_deg)
    out << "Mapping.mono_min_parallax_deg: " << real_text(*s.mapping.mono_min_parallax_deg)
        << "\n\n";
  out << "loopClosing: " << (s.loop_closing.enabled ? 1 : 0) << "\n";
  if (!s.loop_closing.vocabulary_path.empty())
    out << "LoopClosing.vocabulary: " << quoted(s.loop_closing.vocabulary_path) << "\n";
  out << "LoopClosing.merge_maps: " << (s.loop_closing.merge_maps ? 1 : 0) << "\n";
  out << "\n";
  const bool small_seed = s.system.seed <= std::uint64_t{std::numeric_limits<int>::max()};
  out << "System.seed: "
      << (small_seed ? std::to_string(s.system.seed) : quoted(std::to_string(s.system.seed)))
      << "\n"
      << "System.deterministic: " << (s.system.deterministic ? 1 : 0) << "\n";
  if (!s.system.load_atlas.empty())
    out << "System.LoadAtlasFromFile: " << quoted(s.system.load_atlas) << "\n";
  if (!s.system.save_atlas.empty())
    out << "System.SaveAtlasToFile: " << quoted(s.system.save_atlas) << "\n";
}

// cv::FileStorage keeps both copies of a repeated key and reads the first, so a line appended to
// change a setting would be ignored without a word.
void reject_repeated_keys(const cv::FileStorage& fs, const std::string& path) {
  std::set<std::string> seen;
  const cv::FileNode root = fs.root();
  for (auto it = root.begin(); it != root.end(); ++it)
    if (!seen.insert((*it).name()).second)
      fail("{}: key '{}' is given more than once", path, (*it).name());
}

}  // namespace

Settings load_settings(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: settings file not found", path);
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    fail("{}: cannot parse the settings file as YAML ({})", path, e.err);
  }
  if (!fs.isOpened()) fail("{}: cannot open the settings file as YAML", path);
  reject_repeated_keys(fs, path);

  const KeyReader keys(fs, path);
  Settings s;
  s.path = path;
  if (is_v1_layout(keys))
    read_v1_layout(keys, s);
  else
    read_old_layout(keys, s);
  // ORB-SLAM3's inertial files give cam0's pose in the IMU frame; evaluation against an IMU-frame
  // ground truth (EuRoC, TUM-VI) can use it.
  if (keys.has("IMU.T_b_c1"))
    s.T_body_cam0 = read_pose_matrix(keys, "IMU.T_b_c1", 4);
  else if (keys.has("Tbc"))
    s.T_body_cam0 = read_pose_matrix(keys, "Tbc", 4);
  s.resize = read_resize(keys);
  read_orb(keys, s.orb);
  read_saliency(keys, s.saliency);
  read_mapping(keys, s.mapping);
  s.loop_closing.enabled = keys.boolean_or("loopClosing", s.loop_closing.enabled);
  s.loop_closing.vocabulary_path =
      keys.optional_string("LoopClosing.vocabulary").value_or(s.loop_closing.vocabulary_path);
  s.loop_closing.merge_maps = keys.boolean_or("LoopClosing.merge_maps", s.loop_closing.merge_maps);
  s.system.seed = read_seed(keys, s.system.seed);
  s.system.deterministic = keys.boolean_or("System.deterministic", s.system.deterministic);
  s.system.load_atlas = keys.optional_string("System.LoadAtlasFromFile").value_or("");
  s.system.save_atlas = keys.optional_string("System.SaveAtlasToFile").value_or("");
  return s;
}

void save_settings(const Settings& s, const std::string& path) {
  std::ofstream out = open_output_file(path);
  out << "%YAML:1.0\n---\n"
      << "# ORB-SLAM3 settings (File.version 1.0) with sba-slam's Saliency.*, Mapping.* and "
         "System.* keys\n"
      << "File.version: \"1.0\"\n\nCamera.type: "
      << (s.camera.model == CameraModel::kKannalaBrandt8 ? "\"KannalaBrandt8\"" : "\"PinHole\"")
      << "\n\n";
  write_camera(out, "Camera1", s.camera);
  out << "Camera.width: " << s.camera.width << "\n"
      << "Camera.height: " << s.camera.height << "\n";
  if (s.resize && s.resize->width > 0) out << "Camera.newWidth: " << s.resize->width << "\n";
  if (s.resize && s.resize->height > 0) out << "Camera.newHeight: " << s.resize->height << "\n";
  out << "Camera.fps: " << real_text(s.camera.fps) << "\n"
      << "Camera.RGB: " << (s.camera.rgb ? 1 : 0) << "\n\n";
  write_stereo(out, s);
  out << "ORBextractor.nFeatures: " << s.orb.n_features << "\n"
      << "ORBextractor.scaleFactor: " << real_text(s.orb.scale_factor) << "\n"
      << "ORBextractor.nLevels: " << s.orb.n_levels << "\n"
      << "ORBextractor.iniThFAST: " << s.orb.ini_th_fast << "\n"
      << "ORBextractor.minThFAST: " << s.orb.min_th_fast << "\n\n";
  write_ours(out, s);
  close_output_file(out, path);
}

}  // namespace sbaslam
