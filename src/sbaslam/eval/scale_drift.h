#pragma once
// Scale drift of a (monocular) estimate along the ground truth: the ground-truth path is cut into
// consecutive segments of L metres, and for each one the ratio of the estimated to the true path
// length says how the local scale wanders; the segment's KITTI-style t_rel and r_rel say how
// much that costs. Computed without alignment (the raw scale a monocular system picked) and after
// one global Sim3 alignment of the whole estimate (what remains once the mean scale is fixed).

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sbaslam/eval/kitti_odometry.h"

namespace sbaslam::eval {

struct ScaleDriftSegment {
  std::size_t first = 0;  // indices in the paired series
  std::size_t last = 0;
  double start_distance = 0.0;    // ground-truth path distance of `first` (m)
  double reference_length = 0.0;  // ground-truth path length first..last (>= L)
  double estimate_length = 0.0;   // estimated path length first..last
  double scale_ratio = 0.0;       // estimate_length / reference_length
  double t_err = 0.0;             // devkit's ||t(E)|| / L, a fraction
  double r_err = 0.0;             // devkit's angle(E) / L, rad/m
};

struct ScaleDriftSummary {
  std::size_t segments = 0;
  double ratio_min = 0.0;
  double ratio_max = 0.0;
  double ratio_mean = 0.0;
  double ratio_spread = 0.0;  // ratio_max / ratio_min: 1 means no drift
  double t_err_mean = 0.0;
  double r_err_mean = 0.0;
};

struct ScaleDriftSeries {
  std::vector<ScaleDriftSegment> segments;
  ScaleDriftSummary summary;
};

struct ScaleDriftResult {
  ScaleDriftSeries unaligned;
  ScaleDriftSeries sim3_aligned;
  Similarity sim3;  // the global alignment applied for sim3_aligned
  double reference_path_length = 0.0;
};

// Consecutive segments: the first starts at pose 0, each ends at the first pose whose path
// distance exceeds its start's by more than `length` (the devkit's rule) and the next starts
// there. A last piece shorter than `length` is dropped.
std::vector<std::pair<std::size_t, std::size_t>> consecutive_segments(
    const std::vector<double>& dist, double length);

// Per-segment ratios and errors of an estimate already paired (and aligned as wanted). Throws
// sbaslam::Error for a non-positive length, series of different sizes, or no full segment.
ScaleDriftSeries scale_drift_series(const PoseSeries& reference, const PoseSeries& estimate,
                                    double segment_length);

// Both series: as given and after a Sim3 Umeyama alignment of all paired positions.
ScaleDriftResult scale_drift(const PoseSeries& reference, const PoseSeries& estimate,
                             double segment_length);

std::string format_scale_drift_table(const TrajectoryPairSettings& input,
                                     const TrajectoryPair& pair, double segment_length,
                                     const ScaleDriftResult& result);
// {"segment_length", "unaligned": {"summary", "segments": [...]}, "sim3_aligned": {...}, ...}.
void write_scale_drift_json(const std::string& path, const TrajectoryPairSettings& input,
                            const TrajectoryPair& pair, double segment_length,
                            const ScaleDriftResult& result);

}  // namespace sbaslam::eval
