#pragma once
// EuRoC MAV (ASL layout): <path> holds mav0/ with cam0/ and optionally cam1/, each with
// data.csv ("#timestamp [ns],filename"), data/*.png and sensor.yaml. Stamps are integer ns and
// are returned in seconds.
//
// Stereo: cam0 and cam1 frames are paired by timestamp (within kMaxPairGapNs); cam0 frames
// without a cam1 partner are skipped with a warning (the recordings do not always start and end
// together), an error if none pair. The pair is rectified with the two sensor.yaml files, so
// load() returns rectified images of a camera rotated from cam0 by calibration().T_cam0_image.
// Monocular (no cam1/ or options.load_right false): raw cam0 images with their distortion.
//
// Without cam0/sensor.yaml (a recording exported to this layout without them) and with
// options.settings, the cameras are the settings file's, as in ORB-SLAM3: Camera2.* and
// Stereo.T_c1_c2 (or Tlr) are rectified as above, ORB-SLAM2's LEFT.* / RIGHT.* rectify the pair
// as they say (and LEFT.* is the monocular camera), and Stereo.b alone (Camera.bf) describes a
// pair rectified before recording, returned as it is. cam0's pose in the body frame is then the
// settings' IMU.T_b_c1 (Tbc), or the identity without it. With cam0/sensor.yaml, the sensor.yaml
// files are used and the settings' cameras are not. Beyond the EuRoC distribution, a depth0/ folder
// laid out like cam0/ (16-bit PNGs registered to cam0, as `sba-slam simulate` writes: metres =
// value / 256) is read with the monocular images, each cam0 frame paired with the depth frame
// nearest in time (within kMaxPairGapNs, or an error): an RGB-D sequence.
//
// Ground truth: mav0/state_groundtruth_estimate0/data.csv when present, T_world_body of the
// body (IMU) frame; cam0's pose is T_world_body * calibration().T_body_cam0.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "sbaslam/core/stereo_rectifier.h"
#include "sbaslam/io/dataset.h"
#include "sbaslam/io/euroc_sensor.h"

namespace sbaslam::io {

class EurocReader : public DatasetReader {
 public:
  static constexpr std::int64_t kMaxPairGapNs = 2'500'000;  // 2.5 ms, well under a frame

  explicit EurocReader(const std::string& dataset_dir, const DatasetOptions& options = {});

  std::string kind() const override { return "euroc"; }
  std::size_t size() const override { return left_.size(); }
  double timestamp(std::size_t i) const override;
  FrameData load(std::size_t i) const override;
  bool has_right() const override { return !right_.empty(); }
  bool has_depth() const override { return !depth_.empty(); }
  std::optional<Trajectory> ground_truth() const override;
  std::optional<DatasetCalibration> calibration() const override { return calibration_; }
  Vec2 file_pixel(const Vec2& image_pixel) const override;

  std::int64_t timestamp_ns(std::size_t i) const { return left_.at(i).stamp_ns; }
  const EurocCameraSensor& cam0() const { return cam0_; }
  // Only with right images.
  const StereoRectifier* rectifier() const { return rectifier_.get(); }
  const std::string& ground_truth_path() const { return ground_truth_path_; }

  struct Entry {
    std::int64_t stamp_ns = 0;
    std::string path;      // image file
    std::size_t line = 0;  // in data.csv, for messages
  };

 private:
  void open_right_camera(const std::filesystem::path& cam1_dir, const Settings* settings);
  void rectify(const CameraSettings& cam1, const SE3& T_cam0_cam1);
  void adopt_rectifier(std::unique_ptr<StereoRectifier> rectifier);
  void pair_stereo(const std::vector<Entry>& right, const std::string& right_csv);
  void pair_depth(const std::vector<Entry>& depth, const std::string& depth_csv);
  static void check_images_exist(const std::vector<Entry>& entries, const std::string& csv);

  std::vector<Entry> left_;
  std::vector<Entry> right_;  // empty (mono) or right_[i] pairs left_[i]
  std::vector<Entry> depth_;  // empty, or depth_[i] is left_[i]'s depth image
  EurocCameraSensor cam0_;
  std::unique_ptr<StereoRectifier> rectifier_;
  DatasetCalibration calibration_;
  std::string calibration_source_;  // cam0's sensor.yaml, or the settings file; for messages
  std::string ground_truth_path_;
};

// Reads a camera's data.csv and checks the stamps increase. Whether the images exist is checked
// only for the frames used (EurocReader), because cam1 listings may run past cam0's.
std::vector<EurocReader::Entry> read_euroc_image_list(const std::string& camera_dir);

}  // namespace sbaslam::io
