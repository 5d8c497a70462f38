#pragma once
// A timestamped sequence of poses. A pose maps the camera (or body) frame into the world frame,
// as in TUM, KITTI and evo. KITTI files carry no stamps: readers fill them with the row index or
// with times.txt.

#include <vector>

#include "sbaslam/core/lie.h"

namespace sbaslam {

struct Trajectory {
  std::vector<double> stamps;  // seconds
  std::vector<SE3> poses;      // T_world_frame

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  void push_back(double stamp, const SE3& pose) {
    stamps.push_back(stamp);
    poses.push_back(pose);
  }
  // Sum of the distances between consecutive positions, in the trajectory's units.
  double path_length() const {
    double length = 0.0;
    for (std::size_t i = 1; i < poses.size(); ++i)
      length += (poses[i].translation() - poses[i - 1].translation()).norm();
    return length;
  }
};

}  // namespace sbaslam
