#pragma once
// KITTI odometry sequence: <path> = .../sequences/XX with image_0/ (left, grayscale), optional
// image_1/ (right), calib.txt (P0, P1: rectified 3x4 projections) and times.txt (seconds).
// Ground truth: .../poses/XX.txt when present, T_world_cam0 of the left camera with the world at
// the first frame's camera, stamped from times.txt. Beyond the KITTI distribution, a depth/
// folder of 16-bit PNGs named like image_0/'s (what `sba-slam simulate` writes: metres = value /
// 256) makes it an RGB-D sequence.

#include <map>
#include <string>
#include <vector>

#include "sbaslam/io/dataset.h"

namespace sbaslam::io {

// The 3x4 rows of a KITTI calib.txt by name: "P0".."P3" (rectified projections) and "Tr"
// (velodyne to cam0), whichever are present. Throws sbaslam::Error naming the file and line for a
// missing file or a malformed row.
std::map<std::string, Mat34> read_kitti_calibration_rows(const std::string& path);

class KittiReader : public DatasetReader {
 public:
  explicit KittiReader(const std::string& sequence_dir, const DatasetOptions& options = {});

  std::string kind() const override { return "kitti"; }
  std::size_t size() const override { return names_.size(); }
  double timestamp(std::size_t i) const override;
  FrameData load(std::size_t i) const override;
  bool has_right() const override { return has_right_; }
  bool has_depth() const override { return has_depth_; }
  std::optional<Trajectory> ground_truth() const override;
  std::optional<DatasetCalibration> calibration() const override { return calibration_; }

  const Mat34& P0() const { return P0_; }
  // Stereo baseline in metres, -P1[0][3] / P1[0][0]; 0 when calib.txt has no P1.
  double baseline() const { return baseline_; }
  // .../poses/XX.txt (may not exist).
  const std::string& poses_path() const { return poses_path_; }

 private:
  void read_calibration(const std::string& calib_path);
  void read_times(const std::string& times_path);

  std::string dir_;
  std::vector<std::string> names_;  // image file names, shared by image_0 and image_1
  std::vector<double> stamps_;
  bool has_right_ = false;
  bool has_depth_ = false;
  Mat34 P0_ = Mat34::Zero();
  double baseline_ = 0.0;
  std::string poses_path_;
  DatasetCalibration calibration_;
};

}  // namespace sbaslam::io
