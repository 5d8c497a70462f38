#pragma once
// The whole evaluation as `sba-slam eval ape|rpe` runs it: read both files, optionally move the
// reference from body to camera frame, associate, align, compute the per-pose or per-pair
// errors and their statistics.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/eval/alignment.h"
#include "sbaslam/eval/association.h"
#include "sbaslam/eval/pose_relation.h"
#include "sbaslam/eval/rpe.h"
#include "sbaslam/eval/statistics.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::eval {

enum class Metric { kApe, kRpe };
std::string metric_name(Metric metric);

struct EvalSettings {
  Metric metric = Metric::kApe;
  // kEuroc: the reference is an EuRoC ground-truth csv and the estimate a TUM file (as evo).
  io::TrajectoryFormat format = io::TrajectoryFormat::kTum;
  std::string reference_path;
  std::string estimate_path;
  AlignmentMode align = AlignmentMode::kNone;
  std::optional<std::size_t> n_to_align;
  PoseRelation relation = PoseRelation::kTransPart;
  AssociationSettings association;
  RpeSettings rpe;  // RPE only
  // EuRoC sensor.yaml (T_BS) or ORB-SLAM3 settings (IMU.T_b_c1 / Tbc): reference T_W_B becomes
  // T_W_B * T_BS.
  std::string ref_body_to_cam_yaml;
};

struct EvalResult {
  std::vector<double> errors;
  // APE: the estimate's stamp of each pose (row index for KITTI). RPE: the pair's two stamps.
  std::vector<double> first_stamps;
  std::vector<double> second_stamps;
  // APE: each matched pose's reference position and the aligned estimate's, for plots.
  std::vector<Vec3> reference_positions;
  std::vector<Vec3> estimate_positions;
  ErrorStatistics stats;
  std::size_t n_reference = 0;  // poses read
  std::size_t n_estimate = 0;
  std::size_t n_matched = 0;  // pose pairs after association
  Similarity alignment;
};

// Reads the files named in the settings and evaluates. Throws sbaslam::Error with a one-line
// message for every invalid input: fewer than 2 matched poses, no overlap in time, no RPE pair.
EvalResult evaluate(const EvalSettings& settings);

// Evaluates series already in memory (the format selects association by time or by row).
EvalResult evaluate(const PoseSeries& reference, const PoseSeries& estimate,
                    const EvalSettings& settings);

}  // namespace sbaslam::eval
