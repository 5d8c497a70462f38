#include "sbaslam/eval/kitti_odometry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::eval {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

AssociatedSeries associate(const PoseSeries& reference, const PoseSeries& estimate,
                           const TrajectoryPairSettings& settings) {
  if (settings.format == io::TrajectoryFormat::kKitti)
    return associate_by_index(reference, estimate);
  return associate_by_time(reference, estimate, settings.association);
}

void validate(const KittiOdometrySettings& settings) {
  if (settings.lengths.empty()) fail("no segment lengths given");
  for (double length : settings.lengths)
    if (!std::isfinite(length) || length <= 0.0)
      fail("segment length {} m is not a positive number", length);
  if (settings.step == 0) fail("the step between segment starts must be at least 1 frame");
}

std::string alignment_text(const TrajectoryPairSettings& input, const TrajectoryPair& pair) {
  if (input.align == AlignmentMode::kNone) return "no alignment";
  std::string text = fmt::format("{} Umeyama alignment", alignment_mode_name(input.align));
  if (input.align != AlignmentMode::kSe3)
    text += fmt::format(", scale correction {}", pair.alignment.scale);
  return text;
}

}  // namespace

TrajectoryPair pair_trajectories(const PoseSeries& reference, const PoseSeries& estimate,
                                 const TrajectoryPairSettings& settings) {
  TrajectoryPair pair;
  pair.n_reference = reference.size();
  pair.n_estimate = estimate.size();
  pair.paired = associate(reference, estimate, settings);
  if (pair.paired.estimate.size() < 2)
    fail(
        "only {} matched pose(s) between the reference ({} poses) and the estimate ({} poses); "
        "at least 2 are needed",
        pair.paired.estimate.size(), reference.size(), estimate.size());
  pair.alignment = align_estimate(pair.paired.estimate, pair.paired.reference, settings.align);
  return pair;
}

TrajectoryPair load_trajectory_pair(const TrajectoryPairSettings& settings) {
  // As `sba-slam eval`: an EuRoC reference is compared with a TUM estimate.
  const io::TrajectoryFormat estimate_format = settings.format == io::TrajectoryFormat::kEuroc
                                                   ? io::TrajectoryFormat::kTum
                                                   : settings.format;
  const PoseSeries reference = io::read_pose_matrices(settings.reference_path, settings.format);
  const PoseSeries estimate = io::read_pose_matrices(settings.estimate_path, estimate_format);
  return pair_trajectories(reference, estimate, settings);
}

std::vector<double> path_distances(const std::vector<Mat4>& poses) {
  std::vector<double> dist;
  dist.reserve(poses.size());
  if (poses.empty()) return dist;
  dist.push_back(0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    dist.push_back(dist.back() +
                   (poses[i].topRightCorner<3, 1>() - poses[i - 1].topRightCorner<3, 1>()).norm());
  return dist;
}

std::optional<std::size_t> segment_end(const std::vector<double>& dist, std::size_t first,
                                       double length) {
  if (first >= dist.size()) return std::nullopt;
  // dist is non-decreasing, so the devkit's linear scan equals the first element > target.
  const auto it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first), dist.end(),
                                   dist[first] + length);
  if (it == dist.end()) return std::nullopt;
  return static_cast<std::size_t>(it - dist.begin());
}

Mat4 segment_error_pose(const std::vector<Mat4>& reference, const std::vector<Mat4>& estimate,
                        std::size_t first, std::size_t last) {
  const Mat4 delta_reference = reference.at(first).inverse() * reference.at(last);
  const Mat4 delta_estimate = estimate.at(first).inverse() * estimate.at(last);
  return delta_estimate.inverse() * delta_reference;
}

double segment_rotation_error(const Mat4& error_pose) {
  const double d = 0.5 * (error_pose(0, 0) + error_pose(1, 1) + error_pose(2, 2) - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

double segment_translation_error(const Mat4& error_pose) {
  return error_pose.topRightCorner<3, 1>().norm();
}

std::vector<double> kitti_default_lengths() {
  return {100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0};
}

double to_percent(double t_err) {
  return 100.0 * t_err;
}

double to_deg_per_100m(double r_err) {
  return 100.0 * kRadToDeg * r_err;
}

double to_deg_per_m(double r_err) {
  return kRadToDeg * r_err;
}

KittiOdometryResult kitti_odometry_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                          const KittiOdometrySettings& settings) {
  validate(settings);
  if (reference.size() != estimate.size())
    fail("the KITTI metric needs paired poses ({} reference, {} estimate)", reference.size(),
         estimate.size());
  KittiOdometryResult result;
  const std::vector<double> dist = path_distances(reference.poses);
  result.reference_path_length = dist.empty() ? 0.0 : dist.back();
  for (double length : settings.lengths) result.per_length.push_back({length, 0, 0.0, 0.0});

  for (std::size_t first = 0; first < reference.size(); first += settings.step) {
    for (KittiLengthSummary& summary : result.per_length) {
      const std::optional<std::size_t> last = segment_end(dist, first, summary.length);
      if (!last) continue;
      const Mat4 E = segment_error_pose(reference.poses, estimate.poses, first, *last);
      KittiSegmentError segment{first, *last, summary.length,
                                segment_translation_error(E) / summary.length,
                                segment_rotation_error(E) / summary.length};
      result.segments.push_back(segment);
      ++summary.segments;
      summary.t_err += segment.t_err;
      summary.r_err += segment.r_err;
      result.t_err += segment.t_err;
      result.r_err += segment.r_err;
    }
  }
  if (result.segments.empty()) {
    const auto shortest = std::min_element(settings.lengths.begin(), settings.lengths.end());
    fail("no segment fits: the shortest length is {} m but the reference path is {} m long",
         *shortest, result.reference_path_length);
  }
  for (KittiLengthSummary& summary : result.per_length) {
    if (summary.segments == 0) continue;
    summary.t_err /= static_cast<double>(summary.segments);
    summary.r_err /= static_cast<double>(summary.segments);
  }
  result.t_err /= static_cast<double>(result.segments.size());
  result.r_err /= static_cast<double>(result.segments.size());
  return result;
}

std::string format_kitti_table(const TrajectoryPairSettings& input, const TrajectoryPair& pair,
                               const KittiOdometrySettings& settings,
                               const KittiOdometryResult& result) {
  std::string text =
      "KITTI odometry drift (devkit evaluate_odometry: segments of ground-truth "
      "path length)\n";
  text += fmt::format("({})\n", alignment_text(input, pair));
  text += fmt::format("format {}, step {} frames", io::trajectory_format_name(input.format),
                      settings.step);
  if (input.format != io::TrajectoryFormat::kKitti)
    text += fmt::format(", t-max-diff {} s, t-offset {} s", input.association.t_max_diff,
                        input.association.t_offset);
  text += fmt::format("\nposes: {} reference, {} estimate, {} paired; reference path {:.1f} m\n\n",
                      pair.n_reference, pair.n_estimate, pair.paired.estimate.size(),
                      result.reference_path_length);
  text += fmt::format("{:>10}  {:>8}  {:>9}  {:>16}\n", "length (m)", "segments", "t_rel (%)",
                      "r_rel (deg/100m)");
  for (const KittiLengthSummary& s : result.per_length) {
    if (s.segments == 0)
      text += fmt::format("{:>10}  {:>8}  {:>9}  {:>16}\n", s.length, 0, "-", "-");
    else
      text += fmt::format("{:>10}  {:>8}  {:>9.4f}  {:>16.4f}\n", s.length, s.segments,
                          to_percent(s.t_err), to_deg_per_100m(s.r_err));
  }
  text += fmt::format("{:>10}  {:>8}  {:>9.4f}  {:>16.4f}\n", "all", result.segments.size(),
                      to_percent(result.t_err), to_deg_per_100m(result.r_err));
  text += fmt::format("\nt_rel {:.4f} %, r_rel {:.4f} deg/100m ({:.6f} deg/m)\n",
                      to_percent(result.t_err), to_deg_per_100m(result.r_err),
                      to_deg_per_m(result.r_err));
  return text;
}

void write_kitti_json(const std::string& path, const TrajectoryPairSettings& input,
                      const TrajectoryPair& pair, const KittiOdometrySettings& settings,
                      const KittiOdometryResult& result) {
  nlohmann::ordered_json json;
  json["t_rel_percent"] = to_percent(result.t_err);
  json["r_rel_deg_per_100m"] = to_deg_per_100m(result.r_err);
  json["r_rel_deg_per_m"] = to_deg_per_m(result.r_err);
  json["segments"] = result.segments.size();
  nlohmann::ordered_json per_length = nlohmann::ordered_json::array();
  for (const KittiLengthSummary& s : result.per_length) {
    nlohmann::ordered_json entry;
    entry["length"] = s.length;
    entry["segments"] = s.segments;
    // null, not 0, when no segment of this length fits: 0 would read as a perfect result.
    entry["t_rel_percent"] =
        s.segments ? nlohmann::ordered_json(to_percent(s.t_err)) : nlohmann::ordered_json(nullptr);
    entry["r_rel_deg_per_100m"] = s.segments ? nlohmann::ordered_json(to_deg_per_100m(s.r_err))
                                             : nlohmann::ordered_json(nullptr);
    per_length.push_back(entry);
  }
  json["per_length"] = per_length;
  json["reference_path_length"] = result.reference_path_length;
  json["step"] = settings.step;
  json["format"] = io::trajectory_format_name(input.format);
  json["reference"] = input.reference_path;
  json["estimate"] = input.estimate_path;
  json["align"] = alignment_mode_name(input.align);
  json["alignment_scale"] = pair.alignment.scale;
  json["t_max_diff"] = input.association.t_max_diff;
  json["t_offset"] = input.association.t_offset;
  json["n_reference"] = pair.n_reference;
  json["n_estimate"] = pair.n_estimate;
  json["n_matched"] = pair.paired.estimate.size();

  write_output_file(path, json.dump(1) + "\n");
}

}  // namespace sbaslam::eval
