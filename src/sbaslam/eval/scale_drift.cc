#include "sbaslam/eval/scale_drift.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::eval {
namespace {

ScaleDriftSummary summarise(const std::vector<ScaleDriftSegment>& segments) {
  ScaleDriftSummary summary;
  summary.segments = segments.size();
  summary.ratio_min = segments.front().scale_ratio;
  summary.ratio_max = segments.front().scale_ratio;
  for (const ScaleDriftSegment& s : segments) {
    summary.ratio_min = std::min(summary.ratio_min, s.scale_ratio);
    summary.ratio_max = std::max(summary.ratio_max, s.scale_ratio);
    summary.ratio_mean += s.scale_ratio;
    summary.t_err_mean += s.t_err;
    summary.r_err_mean += s.r_err;
  }
  const double n = static_cast<double>(segments.size());
  summary.ratio_mean /= n;
  summary.t_err_mean /= n;
  summary.r_err_mean /= n;
  // A collapsed estimate (ratio 0) has an unbounded spread; JSON cannot hold infinity.
  summary.ratio_spread =
      summary.ratio_min > 0.0 ? summary.ratio_max / summary.ratio_min : std::nan("");
  return summary;
}

nlohmann::ordered_json series_json(const ScaleDriftSeries& series) {
  const ScaleDriftSummary& s = series.summary;
  nlohmann::ordered_json summary;
  summary["segments"] = s.segments;
  summary["ratio_min"] = s.ratio_min;
  summary["ratio_max"] = s.ratio_max;
  summary["ratio_mean"] = s.ratio_mean;
  summary["ratio_spread"] = std::isfinite(s.ratio_spread) ? nlohmann::ordered_json(s.ratio_spread)
                                                          : nlohmann::ordered_json(nullptr);
  summary["t_rel_percent_mean"] = to_percent(s.t_err_mean);
  summary["r_rel_deg_per_100m_mean"] = to_deg_per_100m(s.r_err_mean);
  nlohmann::ordered_json segments = nlohmann::ordered_json::array();
  for (const ScaleDriftSegment& segment : series.segments) {
    nlohmann::ordered_json entry;
    entry["first"] = segment.first;
    entry["last"] = segment.last;
    entry["start_distance"] = segment.start_distance;
    entry["reference_length"] = segment.reference_length;
    entry["estimate_length"] = segment.estimate_length;
    entry["scale_ratio"] = segment.scale_ratio;
    entry["t_rel_percent"] = to_percent(segment.t_err);
    entry["r_rel_deg_per_100m"] = to_deg_per_100m(segment.r_err);
    segments.push_back(entry);
  }
  nlohmann::ordered_json json;
  json["summary"] = summary;
  json["segments"] = segments;
  return json;
}

std::string summary_line(const char* name, const ScaleDriftSummary& s) {
  return fmt::format(
      "{:<13} ratio min {:.4f}, max {:.4f}, mean {:.4f}, max/min {:.4f}; mean t_rel {:.4f} %, "
      "mean r_rel {:.4f} deg/100m\n",
      name, s.ratio_min, s.ratio_max, s.ratio_mean, s.ratio_spread, to_percent(s.t_err_mean),
      to_deg_per_100m(s.r_err_mean));
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> consecutive_segments(
    const std::vector<double>& dist, double length) {
  std::vector<std::pair<std::size_t, std::size_t>> segments;
  std::size_t first = 0;
  while (const std::optional<std::size_t> last = segment_end(dist, first, length)) {
    segments.emplace_back(first, *last);
    first = *last;
  }
  return segments;
}

ScaleDriftSeries scale_drift_series(const PoseSeries& reference, const PoseSeries& estimate,
                                    double segment_length) {
  if (!std::isfinite(segment_length) || segment_length <= 0.0)
    fail("segment length {} m is not a positive number", segment_length);
  if (reference.size() != estimate.size())
    fail("scale drift needs paired poses ({} reference, {} estimate)", reference.size(),
         estimate.size());
  const std::vector<double> ref_dist = path_distances(reference.poses);
  const std::vector<double> est_dist = path_distances(estimate.poses);
  ScaleDriftSeries series;
  for (const auto& [first, last] : consecutive_segments(ref_dist, segment_length)) {
    ScaleDriftSegment s;
    s.first = first;
    s.last = last;
    s.start_distance = ref_dist[first];
    s.reference_length = ref_dist[last] - ref_dist[first];
    s.estimate_length = est_dist[last] - est_dist[first];
    s.scale_ratio = s.estimate_length / s.reference_length;
    const Mat4 E = segment_error_pose(reference.poses, estimate.poses, first, last);
    s.t_err = segment_translation_error(E) / segment_length;
    s.r_err = segment_rotation_error(E) / segment_length;
    series.segments.push_back(s);
  }
  if (series.segments.empty())
    fail("no full {} m segment: the reference path is {} m long", segment_length,
         ref_dist.empty() ? 0.0 : ref_dist.back());
  series.summary = summarise(series.segments);
  return series;
}

ScaleDriftResult scale_drift(const PoseSeries& reference, const PoseSeries& estimate,
                             double segment_length) {
  ScaleDriftResult result;
  result.unaligned = scale_drift_series(reference, estimate, segment_length);
  PoseSeries aligned = estimate;
  result.sim3 = align_estimate(aligned, reference, AlignmentMode::kSim3);
  result.sim3_aligned = scale_drift_series(reference, aligned, segment_length);
  const std::vector<double> dist = path_distances(reference.poses);
  result.reference_path_length = dist.back();
  return result;
}

std::string format_scale_drift_table(const TrajectoryPairSettings& input,
                                     const TrajectoryPair& pair, double segment_length,
                                     const ScaleDriftResult& result) {
  std::string text = fmt::format(
      "Scale drift per {} m of ground-truth path (ratio = estimated / true path length)\n",
      segment_length);
  text += fmt::format("format {}", io::trajectory_format_name(input.format));
  if (input.format != io::TrajectoryFormat::kKitti)
    text += fmt::format(", t-max-diff {} s, t-offset {} s", input.association.t_max_diff,
                        input.association.t_offset);
  text += fmt::format(
      "\nposes: {} reference, {} estimate, {} paired; reference path {:.1f} m; global Sim3 "
      "scale correction {}\n\n",
      pair.n_reference, pair.n_estimate, pair.paired.estimate.size(), result.reference_path_length,
      result.sim3.scale);
  text +=
      fmt::format("{:>7}  {:>10}  {:>12}  {:>11}  {:>13}  {:>12}  {:>14}\n", "segment", "start (m)",
                  "frames", "ratio (raw)", "t_rel (raw,%)", "ratio (sim3)", "t_rel (sim3,%)");
  for (std::size_t k = 0; k < result.unaligned.segments.size(); ++k) {
    const ScaleDriftSegment& raw = result.unaligned.segments[k];
    const ScaleDriftSegment& sim3 = result.sim3_aligned.segments[k];
    text +=
        fmt::format("{:>7}  {:>10.1f}  {:>12}  {:>11.4f}  {:>13.4f}  {:>12.4f}  {:>14.4f}\n", k,
                    raw.start_distance, fmt::format("{}-{}", raw.first, raw.last), raw.scale_ratio,
                    to_percent(raw.t_err), sim3.scale_ratio, to_percent(sim3.t_err));
  }
  text += "\n" + summary_line("unaligned:", result.unaligned.summary);
  text += summary_line("sim3-aligned:", result.sim3_aligned.summary);
  return text;
}

void write_scale_drift_json(const std::string& path, const TrajectoryPairSettings& input,
                            const TrajectoryPair& pair, double segment_length,
                            const ScaleDriftResult& result) {
  nlohmann::ordered_json json;
  json["segment_length"] = segment_length;
  json["reference_path_length"] = result.reference_path_length;
  json["sim3_scale"] = result.sim3.scale;
  json["unaligned"] = series_json(result.unaligned);
  json["sim3_aligned"] = series_json(result.sim3_aligned);
  json["format"] = io::trajectory_format_name(input.format);
  json["reference"] = input.reference_path;
  json["estimate"] = input.estimate_path;
  json["t_max_diff"] = input.association.t_max_diff;
  json["t_offset"] = input.association.t_offset;
  json["n_reference"] = pair.n_reference;
  json["n_estimate"] = pair.n_estimate;
  json["n_matched"] = pair.paired.estimate.size();

  write_output_file(path, json.dump(1) + "\n");
}

}  // namespace sbaslam::eval
