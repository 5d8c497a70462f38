#include "sbaslam/io/dataset_geometry.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>

#include "sbaslam/core/error.h"

namespace sbaslam::io {

bool settings_fx_disagrees(const Settings& settings, const DatasetCalibration& calib) {
  // A calibration taken from the settings file itself cannot contradict it: with ORB-SLAM2's
  // LEFT.* keys the monocular camera is LEFT.K, while Camera.* describes the rectified images.
  if (calib.from_settings) return false;
  // A settings file describing the raw cameras of a rig the reader rectifies is expected to
  // differ; only a rectified or monocular description is compared.
  const bool reader_rectifies =
      calib.T_cam0_image.so3().angle() > 0.0 || calib.camera.model != settings.camera.model;
  const double fx_file = settings.camera.intrinsics.fx;
  const double fx_data = calib.camera.intrinsics.fx;
  return !reader_rectifies && fx_file > 0.0 && std::abs(fx_file - fx_data) > 0.01 * fx_data;
}

DatasetGeometry resolve_geometry(const Settings& settings, const DatasetReader& reader,
                                 const std::string& dataset_path, bool stereo, bool rgbd) {
  DatasetGeometry g{settings.camera, settings.stereo, SE3(), std::nullopt};
  // calib.txt would replace the lens with rectified pinhole projections without a word.
  if (reader.kind() == "kitti" && settings.camera.model == CameraModel::kKannalaBrandt8)
    fail(
        "{}: Camera.type is \"KannalaBrandt8\", but the KITTI layout's calib.txt describes "
        "rectified pinhole images; give fisheye images in the EuRoC layout (sensor.yaml "
        "\"equidistant\") or the TUM layout",
        settings.path);
  if (reader.kind() == "kitti" && settings.stereo.precomputed)
    fail(
        "{}: LEFT.* / RIGHT.* rectify raw images, but the KITTI layout's images are rectified "
        "already (calib.txt); remove those keys",
        settings.path);
  if (const std::optional<DatasetCalibration> calib = reader.calibration()) {
    if (settings_fx_disagrees(settings, *calib))
      spdlog::warn(
          "{}: Camera fx {} differs from the dataset's calibration ({}); using the "
          "dataset's",
          settings.path, settings.camera.intrinsics.fx, calib->camera.intrinsics.fx);
    const double fps = g.camera.fps;
    g.camera = calib->camera;
    if (g.camera.fps <= 0.0) g.camera.fps = fps;
    g.T_cam0_image = calib->T_cam0_image;
    if (calib->stereo) {
      g.stereo.enabled = true;
      g.stereo.baseline = calib->stereo->baseline;
      g.stereo.bf = calib->stereo->bf;
      g.stereo.right.reset();
      g.stereo.precomputed.reset();  // the reader has rectified the images
    }
  }
  if (settings.resize) {
    g.scaling = image_scaling(*settings.resize, {g.camera.width, g.camera.height}, settings.path);
    g.camera = g.scaling->scaled(g.camera);
    g.stereo.bf *= g.scaling->sx();
  }
  if (stereo) {
    if (!reader.has_right())
      fail("{}: --sensor stereo needs right images, and this {} dataset has none", dataset_path,
           reader.kind());
    if (g.stereo.bf <= 0.0)
      fail("{}: stereo needs a baseline (Camera.bf or Stereo.b)", settings.path);
    if (g.stereo.th_depth <= 0.0) g.stereo.th_depth = 40.0;
  }
  if (rgbd) {
    if (!reader.has_depth())
      fail("{}: --sensor rgbd needs depth images, and this {} dataset has none", dataset_path,
           reader.kind());
    if (g.stereo.bf <= 0.0)
      fail("{}: RGB-D needs Camera.bf (baseline times fx of the virtual stereo pair)",
           settings.path);
    if (g.stereo.th_depth <= 0.0) g.stereo.th_depth = 40.0;
  }
  return g;
}

}  // namespace sbaslam::io
