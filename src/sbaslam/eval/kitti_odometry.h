#pragma once
// The KITTI odometry benchmark's drift metric (the devkit's evaluate_odometry): for every start
// frame i (every `step` frames) and every segment length L, the first frame j whose ground-truth
// path distance exceeds dist(i) + L closes a segment; its error pose is
//   E = inv(inv(P_i) P_j) * inv(Q_i) Q_j      (P estimate, Q ground truth, as the devkit)
// with t_err = ||t(E)|| / L and r_err = acos((trace(R(E)) - 1) / 2) / L, averaged over segments.
// Also the loading shared by the KITTI-style metrics: read, pair (row by row or by time) and align.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/eval/alignment.h"
#include "sbaslam/eval/association.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::eval {

// ---- Loading ----------------------------------------------------------------------------------

struct TrajectoryPairSettings {
  // kKitti pairs row by row; kTum by nearest stamp; kEuroc: the reference is an EuRoC
  // ground-truth csv and the estimate a TUM file, paired by stamp (as `sba-slam eval`).
  io::TrajectoryFormat format = io::TrajectoryFormat::kKitti;
  std::string reference_path;
  std::string estimate_path;
  AssociationSettings association;
  AlignmentMode align = AlignmentMode::kNone;
};

struct TrajectoryPair {
  AssociatedSeries paired;  // the estimate already aligned
  std::size_t n_reference = 0;
  std::size_t n_estimate = 0;
  Similarity alignment;  // identity for kNone
};

// Reads, pairs and aligns. Throws sbaslam::Error for unreadable files, fewer than 2 pairs, ...
TrajectoryPair load_trajectory_pair(const TrajectoryPairSettings& settings);
// Pairs and aligns series already in memory.
TrajectoryPair pair_trajectories(const PoseSeries& reference, const PoseSeries& estimate,
                                 const TrajectoryPairSettings& settings);

// ---- The devkit's segments ---------------------------------------------------------------------

// Cumulative path distance of each pose (dist[0] = 0), from the positions.
std::vector<double> path_distances(const std::vector<Mat4>& poses);

// The devkit's lastFrameFromSegmentLength: the first j >= first with dist[j] > dist[first] + L,
// or nothing when the path ends before.
std::optional<std::size_t> segment_end(const std::vector<double>& dist, std::size_t first,
                                       double length);

// The devkit's error pose of the segment (first, last): inv(inv(P_i) P_j) * inv(Q_i) Q_j, with
// general matrix inverses (KITTI rotations are not exactly orthonormal).
Mat4 segment_error_pose(const std::vector<Mat4>& reference, const std::vector<Mat4>& estimate,
                        std::size_t first, std::size_t last);
// The devkit's rotationError: acos(clamp((trace(R) - 1) / 2, -1, 1)), radians.
double segment_rotation_error(const Mat4& error_pose);
// The devkit's translationError: ||t||.
double segment_translation_error(const Mat4& error_pose);

// ---- The metric --------------------------------------------------------------------------------

// 100, 200, ..., 800 m.
std::vector<double> kitti_default_lengths();

struct KittiOdometrySettings {
  std::vector<double> lengths = kitti_default_lengths();  // metres of ground-truth path
  std::size_t step = 10;  // frames between segment starts (1 s at KITTI's 10 Hz)
};

struct KittiSegmentError {
  std::size_t first = 0;  // index in the paired series
  std::size_t last = 0;
  double length = 0.0;  // the nominal L (m)
  double t_err = 0.0;   // ||t(E)|| / L, a fraction
  double r_err = 0.0;   // angle(E) / L, rad/m
};

struct KittiLengthSummary {
  double length = 0.0;
  std::size_t segments = 0;
  double t_err = 0.0;  // means over this length's segments (0 when there are none)
  double r_err = 0.0;
};

struct KittiOdometryResult {
  std::vector<KittiSegmentError> segments;  // in the devkit's order: by start, then by length
  std::vector<KittiLengthSummary> per_length;
  double t_err = 0.0;  // mean over all segments, fraction
  double r_err = 0.0;  // mean over all segments, rad/m
  double reference_path_length = 0.0;
};

// Unit conversions of the published numbers.
double to_percent(double t_err);
double to_deg_per_100m(double r_err);
double to_deg_per_m(double r_err);

// Throws sbaslam::Error for invalid settings (no or non-positive lengths, step 0), series of
// different sizes, or when no segment fits in the reference path.
KittiOdometryResult kitti_odometry_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                          const KittiOdometrySettings& settings);

// ---- Report ------------------------------------------------------------------------------------

std::string format_kitti_table(const TrajectoryPairSettings& input, const TrajectoryPair& pair,
                               const KittiOdometrySettings& settings,
                               const KittiOdometryResult& result);
// {"t_rel_percent", "r_rel_deg_per_100m", "r_rel_deg_per_m", "segments", "per_length": [...],
// plus the options used}.
void write_kitti_json(const std::string& path, const TrajectoryPairSettings& input,
                      const TrajectoryPair& pair, const KittiOdometrySettings& settings,
                      const KittiOdometryResult& result);

}  // namespace sbaslam::eval
