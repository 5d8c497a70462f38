#pragma once
// Umeyama alignment of an estimate onto a reference, as evo's PoseTrajectory3D.align.

#include <cstddef>
#include <optional>
#include <string>

#include "sbaslam/eval/association.h"

namespace sbaslam::eval {

enum class AlignmentMode { kNone, kSe3, kSim3, kScale };

// "none", "se3", "sim3" or "scale"; anything else throws sbaslam::Error.
AlignmentMode parse_alignment_mode(const std::string& name);
std::string alignment_mode_name(AlignmentMode mode);

// y ~ scale * R * x + t, least squares over the points (Umeyama 1991).
struct Similarity {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
  double scale = 1.0;
};

// x and y are 3 x n, column i of x paired with column i of y. Throws sbaslam::Error when the
// sizes differ, n < 2, or the points are degenerate (covariance rank below 2).
Similarity umeyama_alignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, bool with_scale);

// Aligns the estimate to the reference (paired pose by pose) on the first n_to_align positions
// (all when unset), then applies it like evo: sim3 scales the positions and left-multiplies
// [R|t]; se3 only left-multiplies; scale only scales the positions. Returns the alignment
// (identity for kNone).
Similarity align_estimate(PoseSeries& estimate, const PoseSeries& reference, AlignmentMode mode,
                          std::optional<std::size_t> n_to_align = std::nullopt);

}  // namespace sbaslam::eval
