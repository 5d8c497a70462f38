#pragma once
// TUM RGB-D sequence: <path> holds rgb.txt and depth.txt ("timestamp filename" per line, '#'
// comments, seconds) and the images they list. Each rgb frame is associated with the depth frame
// nearest in time, greedily by smallest difference and below kMaxAssociationGap (as TUM's
// associate.py with its defaults); rgb frames without a depth partner are skipped. Without
// depth.txt (or with options.load_depth false) every rgb frame is returned, monocular. Colour
// images are returned as 8-bit grayscale, depth as raw 16-bit values (TUM: 5000 per metre).
//
// Ground truth: groundtruth.txt when present (TUM format), T_world_camera of the colour
// camera's optical centre in the motion-capture world frame, at the mocap rate (not per frame).

#include <string>
#include <utility>
#include <vector>

#include "sbaslam/io/dataset.h"

namespace sbaslam::io {

class TumReader : public DatasetReader {
 public:
  static constexpr double kMaxAssociationGap = 0.02;  // seconds

  explicit TumReader(const std::string& dataset_dir, const DatasetOptions& options = {});

  std::string kind() const override { return "tum"; }
  std::size_t size() const override { return frames_.size(); }
  double timestamp(std::size_t i) const override { return frames_.at(i).rgb_stamp; }
  FrameData load(std::size_t i) const override;
  bool has_depth() const override { return has_depth_; }
  std::optional<Trajectory> ground_truth() const override;
  // Stamp of the depth image associated with frame i (equal to timestamp(i) without depth).
  double depth_timestamp(std::size_t i) const { return frames_.at(i).depth_stamp; }

 private:
  struct Frame {
    double rgb_stamp = 0.0, depth_stamp = 0.0;
    std::string rgb_path, depth_path;
  };

  std::vector<Frame> frames_;
  bool has_depth_ = false;
  std::string ground_truth_path_;
};

struct TumListEntry {
  double stamp = 0.0;
  std::string path;
};
// Reads rgb.txt / depth.txt: checks the listed files exist and the stamps increase.
std::vector<TumListEntry> read_tum_image_list(const std::string& list_path);
// Pairs (index in a, index in b) with |a - b| < max_gap, chosen greedily by smallest gap, each
// index used once, sorted by a (the algorithm of associate.py). Inputs are sorted.
std::vector<std::pair<std::size_t, std::size_t>> associate_stamps(const std::vector<double>& a,
                                                                  const std::vector<double>& b,
                                                                  double max_gap);

}  // namespace sbaslam::io
