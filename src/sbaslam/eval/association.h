#pragma once
// Pairs the poses of a reference and an estimate: by nearest timestamp (TUM, EuRoC), as evo's
// associate_trajectories does, or row by row (KITTI).

#include <cstddef>
#include <vector>

#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::eval {

using PoseSeries = io::PoseMatrixSeries;

struct AssociationSettings {
  double t_max_diff = 0.01;  // seconds; a pair is kept if |t_ref - (t_est + t_offset)| <= this
  double t_offset = 0.0;     // seconds, added to the estimate's stamps
};

struct AssociatedSeries {
  PoseSeries reference;
  PoseSeries estimate;
  std::vector<std::size_t> reference_ids;  // row of each kept pose in the input
  std::vector<std::size_t> estimate_ids;
};

// evo's semantics: iterate over the shorter series' stamps (over the estimate when the lengths
// are equal) and take the first argmin of |t_long - t_short| in the other, with the offset
// applied like evo. Throws sbaslam::Error when the stamps do not overlap in time or no pair is
// within t_max_diff.
AssociatedSeries associate_by_time(const PoseSeries& reference, const PoseSeries& estimate,
                                   const AssociationSettings& settings);

// KITTI: pose i with pose i. Throws sbaslam::Error when the lengths differ.
AssociatedSeries associate_by_index(const PoseSeries& reference, const PoseSeries& estimate);

// Keeps the given rows.
PoseSeries select_poses(const PoseSeries& series, const std::vector<std::size_t>& ids);

}  // namespace sbaslam::eval
