#include "sbaslam/io/kitti_reader.h"

#include <filesystem>
#include <map>

#include "sbaslam/core/error.h"
#include "sbaslam/io/image_io.h"
#include "sbaslam/io/text_lines.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::io {
namespace fs = std::filesystem;

std::map<std::string, Mat34> read_kitti_calibration_rows(const std::string& path) {
  if (!fs::is_regular_file(path)) fail("{}: calibration file not found", path);
  std::map<std::string, Mat34> projections;
  for (const TextLine& line : read_data_lines(path)) {
    const auto colon = line.text.find(':');
    if (colon == std::string::npos) fail("{}:{}: expected 'NAME: values'", path, line.number);
    const std::string name = line.text.substr(0, colon);
    const auto fields = split_fields(line.text.substr(colon + 1), " \t");
    if (!(name.size() == 2 && name[0] == 'P') && name != "Tr") continue;
    if (fields.size() != 12)
      fail("{}:{}: {} has {} values, expected 12", path, line.number, name, fields.size());
    Mat34 P;
    for (int k = 0; k < 12; ++k)
      P(k / 4, k % 4) =
          parse_number(fields[static_cast<std::size_t>(k)], path, line.number, name.c_str());
    projections[name] = P;
  }
  return projections;
}

namespace {

std::string sequence_folder(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.string();
}

}  // namespace

KittiReader::KittiReader(const std::string& sequence_dir, const DatasetOptions& options)
    : dir_(sequence_folder(sequence_dir)) {
  const fs::path dir(dir_);
  if (!fs::is_directory(dir / "image_0")) fail("{}: no image_0/ folder", dir_);
  names_ = list_files((dir / "image_0").string(), ".png");
  if (names_.empty()) fail("{}: no .png images (empty sequence)", (dir / "image_0").string());

  const fs::path right_dir = dir / "image_1";
  has_right_ = options.load_right && fs::is_directory(right_dir);
  if (has_right_) {
    const auto right_names = list_files(right_dir.string(), ".png");
    if (right_names.size() != names_.size())
      fail("{}: {} right images but {} left images in image_0/", right_dir.string(),
           right_names.size(), names_.size());
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (right_names[i] != names_[i])
        fail("{}: right image '{}' has no left partner (image_0/ has '{}')", right_dir.string(),
             right_names[i], names_[i]);
  }
  const fs::path depth_dir = dir / "depth";
  has_depth_ = options.load_depth && fs::is_directory(depth_dir);
  if (has_depth_)
    for (const std::string& name : names_)
      if (!fs::is_regular_file(depth_dir / name))
        fail("{}: no depth image '{}' for image_0/{}", depth_dir.string(), name, name);
  read_calibration((dir / "calib.txt").string());
  read_times((dir / "times.txt").string());
  poses_path_ =
      (dir.parent_path().parent_path() / "poses" / (dir.filename().string() + ".txt")).string();
}

void KittiReader::read_calibration(const std::string& calib_path) {
  const auto projections = read_kitti_calibration_rows(calib_path);
  const auto p0 = projections.find("P0");
  if (p0 == projections.end()) fail("{}: no P0 row", calib_path);
  P0_ = p0->second;
  if (!(P0_(0, 0) > 0.0) || !(P0_(1, 1) > 0.0))
    fail("{}: P0 has a non-positive focal length", calib_path);
  const auto p1 = projections.find("P1");
  if (p1 != projections.end()) baseline_ = -p1->second(0, 3) / p1->second(0, 0);
  if (has_right_ && !(baseline_ > 0.0))
    fail(
        "{}: {} (needs a P1 row with a positive baseline -P1[0][3]/P1[0][0] for the right "
        "images)",
        calib_path, p1 == projections.end() ? "no P1 row" : "P1 gives a non-positive baseline");

  CameraSettings& camera = calibration_.camera;
  camera.intrinsics = {P0_(0, 0), P0_(1, 1), P0_(0, 2), P0_(1, 2)};
  camera.fps = 10.0;
  camera.rgb = false;
  const std::string first = (fs::path(dir_) / "image_0" / names_.front()).string();
  if (const auto size = read_png_size(first)) {
    camera.width = size->width;
    camera.height = size->height;
  }
  if (has_right_) calibration_.stereo = StereoRig(camera.intrinsics, baseline_);
}

void KittiReader::read_times(const std::string& times_path) {
  for (const TextLine& line : read_data_lines(times_path)) {
    const auto fields = split_fields(line.text, " \t");
    if (fields.size() != 1)
      fail("{}:{}: expected one timestamp, got {} fields", times_path, line.number, fields.size());
    stamps_.push_back(parse_number(fields[0], times_path, line.number, "timestamp"));
  }
  if (stamps_.size() != names_.size())
    fail("{}: {} timestamps for {} images in image_0/", times_path, stamps_.size(), names_.size());
  check_increasing_stamps(stamps_, times_path);
}

double KittiReader::timestamp(std::size_t i) const {
  return stamps_.at(i);
}

namespace {

// An image of `kind` ("right", "depth") decoded by `read`, which must have the left image's size.
cv::Mat read_beside_left(const std::string& path, cv::Mat (*read)(const std::string&),
                         const cv::Mat& left, const char* kind) {
  cv::Mat image = read(path);
  if (image.size() != left.size())
    fail("{}: {} image is {}x{}, the left one {}x{}", path, kind, image.cols, image.rows, left.cols,
         left.rows);
  return image;
}

}  // namespace

FrameData KittiReader::load(std::size_t i) const {
  FrameData frame;
  frame.index = i;
  frame.timestamp = stamps_.at(i);
  frame.left_path = (fs::path(dir_) / "image_0" / names_[i]).string();
  frame.left = read_gray_image(frame.left_path);
  if (has_right_)
    frame.right = read_beside_left((fs::path(dir_) / "image_1" / names_[i]).string(),
                                   read_gray_image, frame.left, "right");
  if (has_depth_)
    frame.depth = read_beside_left((fs::path(dir_) / "depth" / names_[i]).string(),
                                   read_depth_image, frame.left, "depth");
  return frame;
}

std::optional<Trajectory> KittiReader::ground_truth() const {
  if (!fs::is_regular_file(poses_path_)) return std::nullopt;
  Trajectory gt = read_kitti_trajectory(poses_path_);
  if (gt.size() != stamps_.size())
    fail("{}: {} poses for {} frames", poses_path_, gt.size(), stamps_.size());
  gt.stamps = stamps_;
  return gt;
}

}  // namespace sbaslam::io
