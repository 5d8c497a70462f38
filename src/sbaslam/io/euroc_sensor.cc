#include "sbaslam/io/euroc_sensor.h"

#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

std::vector<double> read_numbers(const cv::FileNode& node, const std::string& key,
                                 const std::string& path, std::size_t expected) {
  if (node.empty() || !node.isSeq()) fail("{}: missing or invalid '{}'", path, key);
  std::vector<double> values;
  for (const auto& item : node) {
    if (!item.isReal() && !item.isInt()) fail("{}: '{}' holds a non-number", path, key);
    values.push_back(static_cast<double>(item));
  }
  if (values.size() != expected)
    fail("{}: '{}' has {} values, expected {}", path, key, values.size(), expected);
  for (double v : values)
    if (!std::isfinite(v)) fail("{}: '{}' holds a non-finite value", path, key);
  return values;
}

cv::FileStorage open_yaml(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail("{}: file not found", path);
  cv::FileStorage fs;
  try {
    fs.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    fail("{}: cannot parse as YAML ({})", path, e.err);
  }
  if (!fs.isOpened()) fail("{}: cannot open as YAML", path);
  return fs;
}

}  // namespace

EurocCameraSensor read_euroc_camera_sensor(const std::string& path) {
  const cv::FileStorage fs = open_yaml(path);

  const std::string model = fs["camera_model"].empty() ? "" : std::string(fs["camera_model"]);
  if (model != "pinhole")
    fail("{}: camera_model '{}' is not supported (pinhole only)", path, model);
  const std::string dist_model =
      fs["distortion_model"].empty() ? "" : std::string(fs["distortion_model"]);
  // Kalibr's "equidistant" model is Kannala-Brandt's (TUM-VI's cameras).
  if (dist_model != "radial-tangential" && dist_model != "equidistant")
    fail("{}: distortion_model '{}' is not supported (radial-tangential or equidistant)", path,
         dist_model);

  const auto T = read_numbers(fs["T_BS"]["data"], "T_BS.data", path, 16);
  const auto K = read_numbers(fs["intrinsics"], "intrinsics", path, 4);
  const auto D = read_numbers(fs["distortion_coefficients"], "distortion_coefficients", path, 4);
  const auto res = read_numbers(fs["resolution"], "resolution", path, 2);

  EurocCameraSensor sensor;
  Mat4 T_BS;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T_BS(r, c) = T[static_cast<std::size_t>(4 * r + c)];
  const Mat3 R = T_BS.topLeftCorner<3, 3>();
  if ((R * R.transpose() - Mat3::Identity()).norm() > 1e-4 || R.determinant() < 0.0)
    fail("{}: T_BS does not hold a rotation", path);
  sensor.T_BS = SE3::from_matrix(T_BS);

  CameraSettings& cam = sensor.camera;
  cam.intrinsics = {K[0], K[1], K[2], K[3]};
  if (K[0] <= 0.0 || K[1] <= 0.0) fail("{}: 'intrinsics' has a non-positive focal length", path);
  if (dist_model == "equidistant") {
    cam.model = CameraModel::kKannalaBrandt8;
    cam.fisheye = {D[0], D[1], D[2], D[3]};
  } else {
    cam.distortion = {D[0], D[1], D[2], D[3], 0.0};
  }
  cam.width = static_cast<int>(res[0]);
  cam.height = static_cast<int>(res[1]);
  if (cam.width <= 0 || cam.height <= 0) fail("{}: 'resolution' must be positive", path);
  cam.fps = fs["rate_hz"].empty() ? 0.0 : static_cast<double>(fs["rate_hz"]);
  cam.rgb = false;
  return sensor;
}

SE3 read_body_camera_pose(const std::string& path) {
  if (!open_yaml(path)["T_BS"].empty()) return read_euroc_camera_sensor(path).T_BS;
  const Settings settings = load_settings(path);
  if (!settings.T_body_cam0)
    fail(
        "{}: no camera pose in the body frame: neither T_BS (an EuRoC sensor.yaml) nor "
        "IMU.T_b_c1 / Tbc (an ORB-SLAM3 settings file)",
        path);
  return *settings.T_body_cam0;
}

}  // namespace sbaslam::io
