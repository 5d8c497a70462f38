#pragma once
// What `sba-slam eval` writes: a table for the terminal, a JSON summary and the per-pose or
// per-pair errors. Numbers keep full precision (shortest text that reads back exactly).

#include <string>

#include "sbaslam/eval/evaluator.h"

namespace sbaslam::eval {

std::string format_table(const EvalSettings& settings, const EvalResult& result);

// {"rmse", "mean", "median", "std", "min", "max", "sse", "n", ...} plus the options used, named
// as in reference_stats.json (metric, format, align, pose_relation, t_max_diff, delta, ...).
void write_json_report(const std::string& path, const EvalSettings& settings,
                       const EvalResult& result);

// APE: "stamp error ref_x ref_y ref_z est_x est_y est_z" per pose (the reference's position and
// the aligned estimate's; python/plot_trajectory.py draws them); RPE: "first_stamp second_stamp
// error" per pair. For KITTI the stamps are row indices.
void write_errors(const std::string& path, const EvalSettings& settings, const EvalResult& result);

}  // namespace sbaslam::eval
