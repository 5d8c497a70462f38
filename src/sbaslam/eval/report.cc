#include "sbaslam/eval/report.h"

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::eval {
namespace {

std::string alignment_description(const EvalSettings& settings, const EvalResult& result) {
  if (settings.align == AlignmentMode::kNone) return "no alignment";
  std::string text = fmt::format("{} Umeyama alignment", alignment_mode_name(settings.align));
  if (settings.n_to_align) text += fmt::format(" on the first {} poses", *settings.n_to_align);
  if (settings.align != AlignmentMode::kSe3)
    text += fmt::format(", scale correction {}", result.alignment.scale);
  return text;
}

std::string options_line(const EvalSettings& settings) {
  std::string line = fmt::format("format {}, {}", io::trajectory_format_name(settings.format),
                                 pose_relation_name(settings.relation));
  if (settings.format != io::TrajectoryFormat::kKitti)
    line += fmt::format(", t-max-diff {} s, t-offset {} s", settings.association.t_max_diff,
                        settings.association.t_offset);
  if (settings.metric == Metric::kRpe)
    line +=
        fmt::format(", delta {} {} ({})", settings.rpe.delta, delta_unit_name(settings.rpe.unit),
                    settings.rpe.all_pairs ? "all pairs" : "consecutive pairs");
  if (!settings.ref_body_to_cam_yaml.empty())
    line += fmt::format(", reference body-to-camera from {}", settings.ref_body_to_cam_yaml);
  return line;
}

}  // namespace

std::string format_table(const EvalSettings& settings, const EvalResult& result) {
  const ErrorStatistics& s = result.stats;
  std::string text = fmt::format("{} w.r.t. {}\n", settings.metric == Metric::kApe ? "APE" : "RPE",
                                 pose_relation_description(settings.relation));
  text += fmt::format("({})\n", alignment_description(settings, result));
  text += fmt::format("{}\n", options_line(settings));
  text += fmt::format("poses: {} reference, {} estimate, {} matched; {} {}\n\n", result.n_reference,
                      result.n_estimate, result.n_matched, s.n,
                      settings.metric == Metric::kApe ? "errors" : "pairs");
  const std::pair<const char*, double> rows[] = {
      {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
      {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
  for (const auto& [name, value] : rows) text += fmt::format("{:>10}  {}\n", name, value);
  return text;
}

void write_json_report(const std::string& path, const EvalSettings& settings,
                       const EvalResult& result) {
  const ErrorStatistics& s = result.stats;
  nlohmann::ordered_json json;
  json["rmse"] = s.rmse;
  json["mean"] = s.mean;
  json["median"] = s.median;
  json["std"] = s.std;
  json["min"] = s.min;
  json["max"] = s.max;
  json["sse"] = s.sse;
  json["n"] = s.n;
  json["n_reference"] = result.n_reference;
  json["n_estimate"] = result.n_estimate;
  json["n_matched"] = result.n_matched;
  json["metric"] = metric_name(settings.metric);
  json["format"] = io::trajectory_format_name(settings.format);
  json["reference"] = settings.reference_path;
  json["estimate"] = settings.estimate_path;
  json["align"] = alignment_mode_name(settings.align);
  json["n_to_align"] = settings.n_to_align ? nlohmann::ordered_json(*settings.n_to_align)
                                           : nlohmann::ordered_json(nullptr);
  json["pose_relation"] = pose_relation_name(settings.relation);
  json["t_max_diff"] = settings.association.t_max_diff;
  json["t_offset"] = settings.association.t_offset;
  json["ref_body_to_cam"] = settings.ref_body_to_cam_yaml;
  if (settings.metric == Metric::kRpe) {
    json["delta"] = settings.rpe.delta;
    json["delta_unit"] = delta_unit_name(settings.rpe.unit);
    json["pairs"] = settings.rpe.all_pairs ? "all" : "consecutive";
    json["rel_delta_tol"] = settings.rpe.rel_delta_tol;
  }
  json["alignment_scale"] = result.alignment.scale;

  write_output_file(path, json.dump(1) + "\n");
}

void write_errors(const std::string& path, const EvalSettings& settings, const EvalResult& result) {
  const bool kitti = settings.format == io::TrajectoryFormat::kKitti;
  const char* stamp = kitti ? "index" : "timestamp";
  std::ofstream out = open_output_file(path);
  if (settings.metric == Metric::kApe)
    out << fmt::format("# {} {} ref_x ref_y ref_z est_x est_y est_z\n", stamp,
                       pose_relation_name(settings.relation));
  else
    out << fmt::format("# first_{} second_{} {}\n", stamp, stamp,
                       pose_relation_name(settings.relation));
  for (std::size_t i = 0; i < result.errors.size(); ++i) {
    if (settings.metric == Metric::kApe) {
      const Vec3& r = result.reference_positions[i];
      const Vec3& e = result.estimate_positions[i];
      out << fmt::format("{} {} {} {} {} {} {} {}\n", result.first_stamps[i], result.errors[i],
                         r.x(), r.y(), r.z(), e.x(), e.y(), e.z());
    } else
      out << fmt::format("{} {} {}\n", result.first_stamps[i], result.second_stamps[i],
                         result.errors[i]);
  }
  close_output_file(out, path);
}

}  // namespace sbaslam::eval
