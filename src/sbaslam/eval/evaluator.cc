#include "sbaslam/eval/evaluator.h"

#include "sbaslam/core/error.h"
#include "sbaslam/eval/ape.h"
#include "sbaslam/io/euroc_sensor.h"

namespace sbaslam::eval {
namespace {

void move_reference_to_camera(PoseSeries& reference, const std::string& body_camera_yaml) {
  const Mat4 T_BS = io::read_body_camera_pose(body_camera_yaml).matrix();
  for (Mat4& T_WB : reference.poses) T_WB = T_WB * T_BS;
}

double path_length(const PoseSeries& series) {
  double length = 0.0;
  for (std::size_t i = 1; i < series.size(); ++i)
    length += (series.poses[i].topRightCorner<3, 1>() - series.poses[i - 1].topRightCorner<3, 1>())
                  .norm();
  return length;
}

AssociatedSeries associate(const PoseSeries& reference, const PoseSeries& estimate,
                           const EvalSettings& settings) {
  if (settings.format == io::TrajectoryFormat::kKitti)
    return associate_by_index(reference, estimate);
  return associate_by_time(reference, estimate, settings.association);
}

void compute_ape(const AssociatedSeries& paired, const EvalSettings& settings, EvalResult& result) {
  result.errors = absolute_pose_errors(paired.reference, paired.estimate, settings.relation);
  result.first_stamps = paired.estimate.stamps;
  result.second_stamps = paired.estimate.stamps;
  for (std::size_t i = 0; i < paired.estimate.size(); ++i) {
    result.reference_positions.push_back(paired.reference.poses[i].topRightCorner<3, 1>());
    result.estimate_positions.push_back(paired.estimate.poses[i].topRightCorner<3, 1>());
  }
}

void compute_rpe(const AssociatedSeries& paired, const EvalSettings& settings, EvalResult& result) {
  const std::vector<IdPair> pairs = select_pairs(paired.estimate.poses, settings.rpe);
  if (pairs.empty())
    fail("no pose pairs {} {} apart among the {} matched poses (path length {} m)",
         settings.rpe.delta, delta_unit_name(settings.rpe.unit), paired.estimate.size(),
         path_length(paired.estimate));
  result.errors = relative_pose_errors(paired.reference, paired.estimate, pairs, settings.relation);
  for (const auto& [i, j] : pairs) {
    result.first_stamps.push_back(paired.estimate.stamps[i]);
    result.second_stamps.push_back(paired.estimate.stamps[j]);
  }
}

}  // namespace

std::string metric_name(Metric metric) {
  return metric == Metric::kApe ? "ape" : "rpe";
}

EvalResult evaluate(const EvalSettings& settings) {
  // evo reads EuRoC ground truth as the reference and a TUM file as the estimate.
  const io::TrajectoryFormat estimate_format = settings.format == io::TrajectoryFormat::kEuroc
                                                   ? io::TrajectoryFormat::kTum
                                                   : settings.format;
  PoseSeries reference = io::read_pose_matrices(settings.reference_path, settings.format);
  const PoseSeries estimate = io::read_pose_matrices(settings.estimate_path, estimate_format);
  if (!settings.ref_body_to_cam_yaml.empty())
    move_reference_to_camera(reference, settings.ref_body_to_cam_yaml);
  return evaluate(reference, estimate, settings);
}

EvalResult evaluate(const PoseSeries& reference, const PoseSeries& estimate,
                    const EvalSettings& settings) {
  if (settings.n_to_align && settings.align == AlignmentMode::kNone)
    fail("n-to-align {} given without an alignment (use --align se3, sim3 or scale)",
         *settings.n_to_align);
  EvalResult result;
  result.n_reference = reference.size();
  result.n_estimate = estimate.size();
  AssociatedSeries paired = associate(reference, estimate, settings);
  result.n_matched = paired.estimate.size();
  if (result.n_matched < 2)
    fail(
        "only {} matched pose(s) between the reference ({} poses) and the estimate ({} poses); "
        "at least 2 are needed",
        result.n_matched, reference.size(), estimate.size());

  result.alignment =
      align_estimate(paired.estimate, paired.reference, settings.align, settings.n_to_align);
  if (settings.metric == Metric::kApe)
    compute_ape(paired, settings, result);
  else
    compute_rpe(paired, settings, result);
  result.stats = compute_statistics(result.errors);
  return result;
}

}  // namespace sbaslam::eval
