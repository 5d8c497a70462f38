#include "sbaslam/io/euroc_reader.h"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "sbaslam/core/error.h"
#include "sbaslam/io/image_io.h"
#include "sbaslam/io/text_lines.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::io {
namespace fs = std::filesystem;

std::vector<EurocReader::Entry> read_euroc_image_list(const std::string& camera_dir) {
  const std::string csv = (fs::path(camera_dir) / "data.csv").string();
  std::vector<EurocReader::Entry> entries;
  std::vector<double> stamps;
  for (const TextLine& line : read_data_lines(csv)) {
    const auto fields = split_fields(line.text, ",");
    if (fields.size() != 2 || fields[1].empty())
      fail("{}:{}: expected 'timestamp,filename'", csv, line.number);
    EurocReader::Entry entry;
    entry.stamp_ns = parse_nanoseconds(fields[0], csv, line.number);
    entry.path = (fs::path(camera_dir) / "data" / fields[1]).string();
    entry.line = line.number;
    if (!entries.empty() && entry.stamp_ns <= entries.back().stamp_ns)
      fail("{}:{}: timestamp {} {} the previous one ({})", csv, line.number, entry.stamp_ns,
           entry.stamp_ns == entries.back().stamp_ns ? "repeats" : "is earlier than",
           entries.back().stamp_ns);
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) fail("{}: no images listed (empty sequence)", csv);
  return entries;
}

EurocReader::EurocReader(const std::string& dataset_dir, const DatasetOptions& options) {
  const fs::path mav0 = fs::path(dataset_dir) / "mav0";
  if (!fs::is_directory(mav0))
    fail("{}: no mav0/ folder (expected the EuRoC ASL layout)", dataset_dir);
  const fs::path cam0_dir = mav0 / "cam0";
  if (!fs::is_directory(cam0_dir)) fail("{}: folder not found", cam0_dir.string());
  const std::string cam0_yaml = (cam0_dir / "sensor.yaml").string();
  // A recording in this layout without sensor.yaml files is calibrated by the settings file
  // alone, as ORB-SLAM3 calibrates every one.
  const Settings* settings =
      options.settings && !fs::exists(cam0_yaml) ? options.settings : nullptr;
  if (settings) {
    // ORB-SLAM2's LEFT.* give the raw camera; Camera.* there describes the rectified images.
    const auto& precomputed = settings->stereo.precomputed;
    cam0_.camera = precomputed ? precomputed->left.raw : settings->camera;
    cam0_.T_BS = settings->T_body_cam0.value_or(SE3());
    calibration_source_ = settings->path;
    spdlog::info("{}: no sensor.yaml; the cameras are those of {}", cam0_dir.string(),
                 settings->path);
  } else {
    cam0_ = read_euroc_camera_sensor(cam0_yaml);
    calibration_source_ = cam0_yaml;
    if (options.settings && options.settings->stereo.precomputed)
      spdlog::info("{}: the sensor.yaml files calibrate the rig; LEFT.* / RIGHT.* of {} are unused",
                   mav0.string(), options.settings->path);
  }
  left_ = read_euroc_image_list(cam0_dir.string());
  calibration_.camera = cam0_.camera;
  calibration_.T_body_cam0 = cam0_.T_BS;
  calibration_.from_settings = settings != nullptr;

  const fs::path cam1_dir = mav0 / "cam1";
  if (options.load_right && fs::is_directory(cam1_dir)) open_right_camera(cam1_dir, settings);
  check_images_exist(left_, (cam0_dir / "data.csv").string());
  const fs::path depth_dir = mav0 / "depth0";
  // The depth images are registered to the raw cam0 images, not to rectified ones.
  if (options.load_depth && right_.empty() && fs::is_directory(depth_dir)) {
    pair_depth(read_euroc_image_list(depth_dir.string()), (depth_dir / "data.csv").string());
    check_images_exist(depth_, (depth_dir / "data.csv").string());
  }
  ground_truth_path_ = (mav0 / "state_groundtruth_estimate0" / "data.csv").string();
}

void EurocReader::open_right_camera(const fs::path& cam1_dir, const Settings* settings) {
  if (!settings) {
    const EurocCameraSensor cam1 = read_euroc_camera_sensor((cam1_dir / "sensor.yaml").string());
    rectify(cam1.camera, cam0_.T_BS.inverse() * cam1.T_BS);
  } else if (settings->stereo.precomputed) {
    adopt_rectifier(std::make_unique<StereoRectifier>(*settings->stereo.precomputed));
  } else if (settings->stereo.right) {
    rectify(*settings->stereo.right, settings->stereo.T_c1_c2);
  } else if (settings->stereo.enabled) {
    // Stereo.b or Camera.bf without a second camera: a pair rectified before it was recorded.
    if (cam0_.camera.model != CameraModel::kPinhole || !cam0_.camera.distortion.is_zero())
      fail(
          "{}: Stereo.b / Camera.bf describe a rectified pair, but the camera has lens "
          "distortion; describe the second camera (Camera2.* with Stereo.T_c1_c2) instead",
          settings->path);
    calibration_.stereo = StereoRig(cam0_.camera.intrinsics, settings->stereo.baseline);
  } else {
    fail(
        "{}: no sensor.yaml, and {} describes no second camera (Camera2.* with Stereo.T_c1_c2 "
        "or Tlr, LEFT.* with RIGHT.*, or Stereo.b)",
        cam1_dir.string(), settings->path);
  }
  pair_stereo(read_euroc_image_list(cam1_dir.string()), (cam1_dir / "data.csv").string());
  check_images_exist(right_, (cam1_dir / "data.csv").string());
}

void EurocReader::rectify(const CameraSettings& cam1, const SE3& T_cam0_cam1) {
  adopt_rectifier(std::make_unique<StereoRectifier>(cam0_.camera, cam1, T_cam0_cam1));
}

void EurocReader::adopt_rectifier(std::unique_ptr<StereoRectifier> rectifier) {
  rectifier_ = std::move(rectifier);
  CameraSettings& camera = calibration_.camera;
  camera.intrinsics = rectifier_->rig().intrinsics;
  camera.model = CameraModel::kPinhole;
  camera.distortion = RadTanDistortion{};
  camera.fisheye = KannalaBrandtDistortion{};
  calibration_.stereo = rectifier_->rig();
  calibration_.T_cam0_image = rectifier_->T_cam0_rect();
}

void EurocReader::check_images_exist(const std::vector<Entry>& entries, const std::string& csv) {
  for (const Entry& entry : entries)
    if (!fs::is_regular_file(entry.path))
      fail("{}:{}: image file {} not found", csv, entry.line, entry.path);
}

void EurocReader::pair_stereo(const std::vector<Entry>& right, const std::string& right_csv) {
  std::vector<Entry> left_paired, right_paired;
  std::size_t j = 0;
  for (const Entry& l : left_) {
    // Both lists are sorted: advance to the right frame nearest in time.
    while (j + 1 < right.size() && std::llabs(right[j + 1].stamp_ns - l.stamp_ns) <=
                                       std::llabs(right[j].stamp_ns - l.stamp_ns))
      ++j;
    if (std::llabs(right[j].stamp_ns - l.stamp_ns) > kMaxPairGapNs) continue;
    left_paired.push_back(l);
    right_paired.push_back(right[j]);
  }
  if (left_paired.empty())
    fail("{}: no cam1 frame lies within {} ms of a cam0 frame", right_csv, kMaxPairGapNs / 1e6);
  if (left_paired.size() < left_.size())
    spdlog::warn("{}: {} of {} cam0 frames have no cam1 frame within {} ms; they are skipped",
                 right_csv, left_.size() - left_paired.size(), left_.size(), kMaxPairGapNs / 1e6);
  left_ = std::move(left_paired);
  right_ = std::move(right_paired);
}

void EurocReader::pair_depth(const std::vector<Entry>& depth, const std::string& depth_csv) {
  std::size_t j = 0;
  for (const Entry& l : left_) {
    while (j + 1 < depth.size() && std::llabs(depth[j + 1].stamp_ns - l.stamp_ns) <=
                                       std::llabs(depth[j].stamp_ns - l.stamp_ns))
      ++j;
    if (std::llabs(depth[j].stamp_ns - l.stamp_ns) > kMaxPairGapNs)
      fail("{}: no depth frame lies within {} ms of the cam0 frame at {} ns", depth_csv,
           kMaxPairGapNs / 1e6, l.stamp_ns);
    depth_.push_back(depth[j]);
  }
}

double EurocReader::timestamp(std::size_t i) const {
  return static_cast<double>(left_.at(i).stamp_ns) * 1e-9;
}

namespace {

cv::Mat read_sized_gray(const std::string& path, const CameraSettings& camera,
                        const std::string& calibration_source) {
  cv::Mat image = read_gray_image(path);
  if (image.cols != camera.width || image.rows != camera.height)
    fail("{}: image is {}x{} but {} gives {}x{}", path, image.cols, image.rows, calibration_source,
         camera.width, camera.height);
  return image;
}

}  // namespace

FrameData EurocReader::load(std::size_t i) const {
  FrameData frame;
  frame.index = i;
  frame.timestamp = timestamp(i);
  frame.left_path = left_.at(i).path;
  cv::Mat left = read_sized_gray(frame.left_path, cam0_.camera, calibration_source_);
  if (right_.empty()) {
    frame.left = std::move(left);
    if (!depth_.empty()) {
      frame.depth = read_depth_image(depth_[i].path);
      if (frame.depth.size() != frame.left.size())
        fail("{}: depth image is {}x{}, the cam0 image {}x{}", depth_[i].path, frame.depth.cols,
             frame.depth.rows, frame.left.cols, frame.left.rows);
    }
    return frame;
  }
  cv::Mat right = read_sized_gray(right_[i].path, cam0_.camera, calibration_source_);
  if (rectifier_) {
    rectifier_->rectify(left, right, frame.left, frame.right);
  } else {
    frame.left = std::move(left);
    frame.right = std::move(right);
  }
  return frame;
}

Vec2 EurocReader::file_pixel(const Vec2& image_pixel) const {
  return rectifier_ ? rectifier_->rectified_to_raw_left(image_pixel) : image_pixel;
}

std::optional<Trajectory> EurocReader::ground_truth() const {
  if (!fs::is_regular_file(ground_truth_path_)) return std::nullopt;
  return read_euroc_groundtruth(ground_truth_path_);
}

}  // namespace sbaslam::io
