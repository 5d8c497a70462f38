#pragma once
// Trajectory files in the three formats evo and the benchmarks use:
//   TUM:   "t x y z qx qy qz qw" per line, '#' comments, seconds;
//   KITTI: 12 numbers per line, the row-major 3x4 matrix [R|t]; no stamps (row index is used);
//   EuRoC: ASL csv, "#timestamp [ns],p_RS_R_x [m],...,q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []".
// Writers keep full precision so that reading back gives the same doubles. Readers throw
// sbaslam::Error naming the file and the line for every malformed input.

#include <string>
#include <vector>

#include "sbaslam/core/trajectory.h"

namespace sbaslam::io {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

// "tum", "kitti" or "euroc"; anything else throws sbaslam::Error.
TrajectoryFormat parse_trajectory_format(const std::string& name);
std::string trajectory_format_name(TrajectoryFormat format);

Trajectory read_tum_trajectory(const std::string& path);
// Stamps are the row index (0, 1, 2, ...).
Trajectory read_kitti_trajectory(const std::string& path);
// ASL state_groundtruth_estimate0/data.csv (or a trajectory written by write_euroc_trajectory):
// ns stamp, position, quaternion w x y z; further columns (velocity, biases) are ignored.
Trajectory read_euroc_groundtruth(const std::string& path);
// Dispatches on the format.
Trajectory read_trajectory(const std::string& path, TrajectoryFormat format);

// The poses as evo reads them, for evaluation: KITTI rotations exactly as written (rounded to
// ~7 digits, so not exactly orthonormal: projecting them onto SO(3) would change small RPE errors
// by more than 1e-6 relative), TUM/EuRoC quaternions turned into matrices with evo's formula.
struct PoseMatrixSeries {
  std::vector<double> stamps;  // seconds; KITTI: row index
  std::vector<Mat4> poses;     // T_world_frame
  std::size_t size() const { return poses.size(); }
};
PoseMatrixSeries read_pose_matrices(const std::string& path, TrajectoryFormat format);

void write_tum_trajectory(const std::string& path, const Trajectory& traj);
void write_kitti_trajectory(const std::string& path, const Trajectory& traj);
// Stamps are written as integer nanoseconds (rounded).
void write_euroc_trajectory(const std::string& path, const Trajectory& traj);
void write_trajectory(const std::string& path, const Trajectory& traj, TrajectoryFormat format);

}  // namespace sbaslam::io
