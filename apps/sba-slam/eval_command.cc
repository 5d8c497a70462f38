// sba-slam eval ape|rpe: trajectory evaluation that reproduces evo's APE and RPE numbers.
// sba-slam eval kitti|scale-drift: the KITTI odometry devkit's drift metric and per-segment scale
// drift.

#include <fmt/format.h>

#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "sbaslam/core/error.h"
#include "sbaslam/eval/evaluator.h"
#include "sbaslam/eval/kitti_odometry.h"
#include "sbaslam/eval/report.h"
#include "sbaslam/eval/scale_drift.h"

namespace sbaslam::cli {
namespace {

// Command-line text, turned into typed settings once the whole line is parsed.
struct EvalArguments {
  eval::Metric metric = eval::Metric::kApe;
  std::string reference;
  std::string estimate;
  std::string format;
  std::string align = "none";
  long long n_to_align = -1;
  std::string pose_relation = "trans_part";
  double t_max_diff = 0.01;
  double t_offset = 0.0;
  std::string ref_body_to_cam;
  std::string json_path;
  std::string errors_path;
  double delta = 1.0;
  std::string delta_unit = "f";
  bool all_pairs = false;
  double rel_delta_tol = 0.1;
};

eval::EvalSettings to_settings(const EvalArguments& args) {
  eval::EvalSettings settings;
  settings.metric = args.metric;
  settings.reference_path = args.reference;
  settings.estimate_path = args.estimate;
  settings.format = io::parse_trajectory_format(args.format);
  settings.align = eval::parse_alignment_mode(args.align);
  if (args.n_to_align != -1) {
    if (args.n_to_align < 2) fail("--n-to-align must be at least 2 (got {})", args.n_to_align);
    settings.n_to_align = static_cast<std::size_t>(args.n_to_align);
  }
  settings.relation = eval::parse_pose_relation(args.pose_relation);
  settings.association.t_max_diff = args.t_max_diff;
  settings.association.t_offset = args.t_offset;
  settings.ref_body_to_cam_yaml = args.ref_body_to_cam;
  settings.rpe.delta = args.delta;
  settings.rpe.unit = eval::parse_delta_unit(args.delta_unit);
  settings.rpe.all_pairs = args.all_pairs;
  settings.rpe.rel_delta_tol = args.rel_delta_tol;
  return settings;
}

void run_eval(const EvalArguments& args) {
  const eval::EvalSettings settings = to_settings(args);
  const eval::EvalResult result = eval::evaluate(settings);
  std::cout << eval::format_table(settings, result) << std::flush;
  if (!args.json_path.empty()) eval::write_json_report(args.json_path, settings, result);
  if (!args.errors_path.empty()) eval::write_errors(args.errors_path, settings, result);
}

void add_common_options(CLI::App& command, EvalArguments& args) {
  command.add_option("REF", args.reference, "reference trajectory (ground truth)")->required();
  command.add_option("EST", args.estimate, "estimated trajectory")->required();
  command
      .add_option("--format", args.format,
                  "kitti | tum | euroc (euroc: REF is an EuRoC ground-truth csv, EST a TUM file)")
      ->required();
  command.add_option("--align", args.align, "none | se3 | sim3 | scale (Umeyama, as evo -a/-s)")
      ->capture_default_str();
  command.add_option("--n-to-align", args.n_to_align,
                     "align on the first N matched poses only (default: all)");
  command
      .add_option("--pose-relation", args.pose_relation,
                  "trans_part | angle_deg | angle_rad | full")
      ->capture_default_str();
  command
      .add_option("--t-max-diff", args.t_max_diff,
                  "max. time difference (s) to pair TUM/EuRoC poses")
      ->capture_default_str();
  command.add_option("--t-offset", args.t_offset, "time offset (s) added to the estimate's stamps")
      ->capture_default_str();
  command.add_option("--ref-body-to-cam", args.ref_body_to_cam,
                     "EuRoC sensor.yaml, or ORB-SLAM3 settings with IMU.T_b_c1 (Tbc): compare "
                     "the camera, T_W_C = T_W_B * T_BS");
  command.add_option("--json", args.json_path, "write the statistics and options as JSON");
  command.add_option("--save-errors", args.errors_path,
                     "write the error of every pose / pair (APE: with the reference's and the "
                     "aligned estimate's positions, for python/plot_trajectory.py)");
}

// Options shared by `eval kitti` and `eval scale-drift`.
struct SegmentArguments {
  std::string reference;
  std::string estimate;
  std::string format;
  std::string align = "none";
  double t_max_diff = 0.01;
  double t_offset = 0.0;
  std::string json_path;
  std::string lengths = "100,200,300,400,500,600,700,800";
  long long step = 10;
  double segment = 100.0;
};

eval::TrajectoryPairSettings to_pair_settings(const SegmentArguments& args) {
  eval::TrajectoryPairSettings settings;
  settings.format = io::parse_trajectory_format(args.format);
  settings.reference_path = args.reference;
  settings.estimate_path = args.estimate;
  settings.align = eval::parse_alignment_mode(args.align);
  settings.association.t_max_diff = args.t_max_diff;
  settings.association.t_offset = args.t_offset;
  return settings;
}

std::vector<double> parse_lengths(const std::string& text) {
  std::vector<double> lengths;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find(',', begin);
    if (end == std::string::npos) end = text.size();
    const std::string field = text.substr(begin, end - begin);
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (field.empty() || used != field.size())
      fail("--lengths: '{}' is not a number (expected e.g. 100,200,400)", field);
    lengths.push_back(value);
    begin = end + 1;
  }
  return lengths;
}

void run_eval_kitti(const SegmentArguments& args) {
  const eval::TrajectoryPairSettings input = to_pair_settings(args);
  eval::KittiOdometrySettings settings;
  settings.lengths = parse_lengths(args.lengths);
  if (args.step < 1) fail("--step must be at least 1 frame (got {})", args.step);
  settings.step = static_cast<std::size_t>(args.step);
  const eval::TrajectoryPair pair = eval::load_trajectory_pair(input);
  const eval::KittiOdometryResult result =
      eval::kitti_odometry_errors(pair.paired.reference, pair.paired.estimate, settings);
  std::cout << eval::format_kitti_table(input, pair, settings, result) << std::flush;
  if (!args.json_path.empty())
    eval::write_kitti_json(args.json_path, input, pair, settings, result);
}

void run_eval_scale_drift(const SegmentArguments& args) {
  const eval::TrajectoryPairSettings input = to_pair_settings(args);
  const eval::TrajectoryPair pair = eval::load_trajectory_pair(input);
  const eval::ScaleDriftResult result =
      eval::scale_drift(pair.paired.reference, pair.paired.estimate, args.segment);
  std::cout << eval::format_scale_drift_table(input, pair, args.segment, result) << std::flush;
  if (!args.json_path.empty())
    eval::write_scale_drift_json(args.json_path, input, pair, args.segment, result);
}

void add_segment_options(CLI::App& command, SegmentArguments& args) {
  command.add_option("REF", args.reference, "reference trajectory (ground truth)")->required();
  command.add_option("EST", args.estimate, "estimated trajectory")->required();
  command
      .add_option("--format", args.format,
                  "kitti (paired row by row) | tum (paired by stamp) | euroc (REF an EuRoC csv, "
                  "EST a TUM file)")
      ->required();
  command
      .add_option("--t-max-diff", args.t_max_diff,
                  "max. time difference (s) to pair TUM/EuRoC poses")
      ->capture_default_str();
  command.add_option("--t-offset", args.t_offset, "time offset (s) added to the estimate's stamps")
      ->capture_default_str();
  command.add_option("--json", args.json_path, "write the results and options as JSON");
}

void add_kitti_subcommands(CLI::App& eval_cmd) {
  auto kitti_args = std::make_shared<SegmentArguments>();
  CLI::App* kitti = eval_cmd.add_subcommand(
      "kitti",
      "KITTI odometry drift (devkit evaluate_odometry): t_rel (%) and r_rel (deg/100m) over "
      "segments of ground-truth path length");
  add_segment_options(*kitti, *kitti_args);
  kitti->add_option("--lengths", kitti_args->lengths, "segment lengths in metres, comma-separated")
      ->capture_default_str();
  kitti->add_option("--step", kitti_args->step, "frames between segment starts (paired poses)")
      ->capture_default_str();
  kitti
      ->add_option("--align", kitti_args->align,
                   "none | se3 | sim3 | scale (Umeyama on all paired poses, before the metric)")
      ->capture_default_str();
  kitti->callback([kitti_args] { run_eval_kitti(*kitti_args); });

  auto drift_args = std::make_shared<SegmentArguments>();
  CLI::App* drift = eval_cmd.add_subcommand(
      "scale-drift",
      "estimated / true path length and t_rel per consecutive ground-truth segment, unaligned "
      "and after a global Sim3 alignment");
  add_segment_options(*drift, *drift_args);
  drift->add_option("--segment", drift_args->segment, "segment length in metres")
      ->capture_default_str();
  drift->callback([drift_args] { run_eval_scale_drift(*drift_args); });
}

}  // namespace

void add_eval_command(CLI::App& app) {
  CLI::App* eval_cmd = app.add_subcommand("eval",
                                          "evaluate a trajectory against ground truth "
                                          "(APE / RPE, numbers as evo v1.36.5; KITTI "
                                          "odometry drift; scale drift)");
  eval_cmd->require_subcommand(1);

  auto ape_args = std::make_shared<EvalArguments>();
  ape_args->metric = eval::Metric::kApe;
  CLI::App* ape = eval_cmd->add_subcommand("ape", "absolute pose error");
  add_common_options(*ape, *ape_args);
  ape->callback([ape_args] { run_eval(*ape_args); });

  auto rpe_args = std::make_shared<EvalArguments>();
  rpe_args->metric = eval::Metric::kRpe;
  CLI::App* rpe = eval_cmd->add_subcommand("rpe", "relative pose error");
  add_common_options(*rpe, *rpe_args);
  rpe->add_option("--delta", rpe_args->delta, "distance between the poses of a pair")->required();
  rpe->add_option("--delta-unit", rpe_args->delta_unit, "f (frames) | m (metres)")->required();
  rpe->add_flag("--all-pairs", rpe_args->all_pairs,
                "use every pose as a pair start, not consecutive pairs");
  rpe->add_option("--rel-delta-tol", rpe_args->rel_delta_tol,
                  "with --all-pairs and metres: keep pairs whose path is within this fraction "
                  "of delta")
      ->capture_default_str();
  rpe->callback([rpe_args] { run_eval(*rpe_args); });

  add_kitti_subcommands(*eval_cmd);
}

}  // namespace sbaslam::cli
