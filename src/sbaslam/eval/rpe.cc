#include "sbaslam/eval/rpe.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

double distance(const Mat4& a, const Mat4& b) {
  return (a.topRightCorner<3, 1>() - b.topRightCorner<3, 1>()).norm();
}

std::vector<IdPair> pairs_by_frames(std::size_t n, std::size_t delta, bool all_pairs) {
  std::vector<IdPair> pairs;
  if (all_pairs) {
    for (std::size_t i = 0; i + delta < n; ++i) pairs.emplace_back(i, i + delta);
  } else {
    for (std::size_t i = 0; i + delta < n; i += delta) pairs.emplace_back(i, i + delta);
  }
  return pairs;
}

std::vector<IdPair> consecutive_pairs_by_path(const std::vector<Mat4>& poses, double delta) {
  std::vector<std::size_t> ids;
  double path = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) path += distance(poses[i], poses[i - 1]);
    if (path >= delta) {
      ids.push_back(i);
      path = 0.0;
    }
  }
  std::vector<IdPair> pairs;
  for (std::size_t k = 0; k + 1 < ids.size(); ++k) pairs.emplace_back(ids[k], ids[k + 1]);
  return pairs;
}

std::vector<IdPair> all_pairs_by_path(const std::vector<Mat4>& poses, double delta, double tol) {
  std::vector<double> accumulated(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    accumulated[i] = accumulated[i - 1] + distance(poses[i], poses[i - 1]);
  std::vector<IdPair> pairs;
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    std::size_t best = i + 1;
    double best_diff = std::abs(accumulated[best] - accumulated[i] - delta);
    for (std::size_t j = i + 2; j < poses.size(); ++j) {
      const double diff = std::abs(accumulated[j] - accumulated[i] - delta);
      if (diff < best_diff) {
        best_diff = diff;
        best = j;
      }
    }
    if (best_diff <= tol) pairs.emplace_back(i, best);
  }
  return pairs;
}

}  // namespace

DeltaUnit parse_delta_unit(const std::string& name) {
  if (name == "f" || name == "frames") return DeltaUnit::kFrames;
  if (name == "m" || name == "meters") return DeltaUnit::kMeters;
  fail("unknown delta unit '{}' (expected f or m)", name);
}

std::string delta_unit_name(DeltaUnit unit) {
  return unit == DeltaUnit::kFrames ? "frames" : "meters";
}

std::vector<IdPair> select_pairs(const std::vector<Mat4>& poses, const RpeSettings& settings) {
  if (!std::isfinite(settings.delta) || settings.delta <= 0.0)
    fail("delta must be a positive number (got {})", settings.delta);
  if (settings.unit == DeltaUnit::kFrames) {
    if (settings.delta != std::floor(settings.delta))
      fail("a delta in frames must be a whole number (got {})", settings.delta);
    // A delta beyond the length gives no pairs; clamping keeps the cast defined.
    const double clamped = std::min(settings.delta, static_cast<double>(poses.size()));
    return pairs_by_frames(poses.size(), static_cast<std::size_t>(clamped), settings.all_pairs);
  }
  if (!settings.all_pairs) return consecutive_pairs_by_path(poses, settings.delta);
  if (!std::isfinite(settings.rel_delta_tol) || settings.rel_delta_tol < 0.0)
    fail("the relative delta tolerance must be non-negative (got {})", settings.rel_delta_tol);
  return all_pairs_by_path(poses, settings.delta, settings.rel_delta_tol * settings.delta);
}

std::vector<double> relative_pose_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                         const std::vector<IdPair>& pairs, PoseRelation relation) {
  if (reference.size() != estimate.size())
    fail("RPE needs paired poses ({} reference, {} estimate)", reference.size(), estimate.size());
  std::vector<double> errors;
  errors.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const Mat4 Q_rel = relative_se3(reference.poses.at(i), reference.poses.at(j));
    const Mat4 P_rel = relative_se3(estimate.poses.at(i), estimate.poses.at(j));
    errors.push_back(pose_error(relative_se3(Q_rel, P_rel), relation));
  }
  return errors;
}

}  // namespace sbaslam::eval
