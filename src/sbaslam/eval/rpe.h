#pragma once
// Relative pose error (evo's RPE): pairs of poses (i, j) chosen on the estimate, and the error
// between the reference's and the estimate's relative motions.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sbaslam/eval/association.h"
#include "sbaslam/eval/pose_relation.h"

namespace sbaslam::eval {

enum class DeltaUnit { kFrames, kMeters };

// "f"/"frames" or "m"/"meters"; anything else throws sbaslam::Error.
DeltaUnit parse_delta_unit(const std::string& name);
std::string delta_unit_name(DeltaUnit unit);

struct RpeSettings {
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::kFrames;
  bool all_pairs = false;
  double rel_delta_tol = 0.1;  // metres with all pairs: keep |path - delta| <= tol * delta
};

using IdPair = std::pair<std::size_t, std::size_t>;

// evo's id_pairs_from_delta on the estimate's poses:
//  frames, consecutive: ids 0, d, 2d, ... and their consecutive pairs;
//  frames, all pairs:   (i, i + d) for every i;
//  metres, consecutive: walk the path, record i whenever the path since the last record
//                       reaches delta, pair consecutive records;
//  metres, all pairs:   for each i the j > i whose path from i is closest to delta, if within
//                       the tolerance.
// Throws sbaslam::Error for a non-positive or non-integer frame delta.
std::vector<IdPair> select_pairs(const std::vector<Mat4>& poses, const RpeSettings& settings);

// Errors of E = inv(inv(Q_i) Q_j) inv(P_i) P_j for each pair, Q reference and P estimate.
std::vector<double> relative_pose_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                         const std::vector<IdPair>& pairs, PoseRelation relation);

}  // namespace sbaslam::eval
