#include "sbaslam/optimize/bundle_adjuster.h"

#include <ceres/ceres.h>

#include <cstdlib>
#include <string>

#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

class AbortCallback : public ceres::IterationCallback {
 public:
  explicit AbortCallback(const std::atomic<bool>* abort) : abort_(abort) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return abort_->load() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::atomic<bool>* abort_;
};

struct Parameters {
  std::vector<PoseParameters> poses;
  std::vector<Vec3> points;
};

Parameters collect_parameters(const BundleAdjustmentProblem& problem) {
  Parameters params;
  params.poses.reserve(problem.keyframes.size());
  for (const BaKeyframe& kf : problem.keyframes) params.poses.push_back(to_parameters(kf.T_cw));
  params.points.reserve(problem.points.size());
  for (const BaPoint& p : problem.points) params.points.push_back(p.position);
  return params;
}

std::vector<bool> classify_outliers(const BundleAdjustmentProblem& problem,
                                    const Parameters& params) {
  std::vector<bool> outlier(problem.observations.size(), false);
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const BaObservation& o = problem.observations[i];
    const ReprojectionCheck check = check_reprojection(
        problem.camera, params.poses[static_cast<std::size_t>(o.keyframe)].data(),
        params.points[static_cast<std::size_t>(o.point)].data(), o.pixel);
    const double threshold = o.pixel.is_stereo() ? kChi2Stereo : kChi2Mono;
    outlier[i] = !check.in_front || check.chi2 > threshold;
  }
  return outlier;
}

// Builds and solves one Ceres problem over the observations not flagged in `skip`.
ceres::Solver::Summary solve(const BundleAdjustmentProblem& problem, Parameters& params,
                             const std::vector<bool>& skip, bool robust, int iterations,
                             const BundleAdjusterOptions& options) {
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  const std::unique_ptr<ceres::Manifold> pose_manifold = make_pose_manifold();
  RotationManifold rotation_manifold;
  auto* ordering = new ceres::ParameterBlockOrdering;

  bool any_stereo = false;
  for (std::size_t i = 0; i < problem.observations.size(); ++i)
    any_stereo = any_stereo || (!skip[i] && problem.observations[i].pixel.is_stereo());
  std::vector<bool> pose_added(problem.keyframes.size(), false);
  std::vector<bool> point_added(problem.points.size(), false);
  int free_keyframes = 0;
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    if (skip[i]) continue;
    const BaObservation& o = problem.observations[i];
    const auto kf = static_cast<std::size_t>(o.keyframe);
    const auto pt = static_cast<std::size_t>(o.point);
    // With stereo observations the pose is two blocks (reprojection_cost.h says why).
    double* pose = params.poses[kf].data();
    double* rotation = rotation_block(params.poses[kf]);
    double* translation = translation_block(params.poses[kf]);
    double* point = params.points[pt].data();
    if (!pose_added[kf]) {
      pose_added[kf] = true;
      std::vector<double*> blocks = {pose};
      if (any_stereo) {
        ceres_problem.AddParameterBlock(rotation, 4, &rotation_manifold);
        ceres_problem.AddParameterBlock(translation, 3);
        blocks = {rotation, translation};
      } else {
        ceres_problem.AddParameterBlock(pose, 7, pose_manifold.get());
      }
      for (double* block : blocks) {
        if (problem.keyframes[kf].fixed) ceres_problem.SetParameterBlockConstant(block);
        ordering->AddElementToGroup(block, 1);
      }
      if (!problem.keyframes[kf].fixed) ++free_keyframes;
    }
    if (!point_added[pt]) {
      point_added[pt] = true;
      ceres_problem.AddParameterBlock(point, 3);
      if (problem.points[pt].fixed) ceres_problem.SetParameterBlockConstant(point);
      ordering->AddElementToGroup(point, 0);
    }
    ceres::LossFunction* loss = nullptr;
    if (robust)
      loss = new ceres::HuberLoss(o.pixel.is_stereo() ? options.huber_stereo : options.huber_mono);
    ceres::CostFunction* cost = make_reprojection_cost(problem.camera, o.pixel, any_stereo);
    if (any_stereo) {
      ceres_problem.AddResidualBlock(cost, loss, rotation, translation, point);
    } else {
      ceres_problem.AddResidualBlock(cost, loss, pose, point);
    }
  }

  ceres::Solver::Options solver;
  if (free_keyframes == 0) {
    // Only points move: the normal equations are block diagonal, no Schur complement to form.
    delete ordering;
    solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  } else {
    solver.linear_solver_type = free_keyframes > options.dense_schur_max_keyframes
                                    ? ceres::SPARSE_SCHUR
                                    : ceres::DENSE_SCHUR;
    solver.linear_solver_ordering.reset(ordering);
  }
  solver.max_num_iterations = iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.num_threads = options.num_threads;
  solver.logging_type = ceres::SILENT;
  AbortCallback abort_callback(options.abort);
  if (options.abort) solver.callbacks.push_back(&abort_callback);
  ceres::Solver::Summary summary;
  if (ceres_problem.NumResidualBlocks() > 0) ceres::Solve(solver, &ceres_problem, &summary);
  return summary;
}

void write_back(BundleAdjustmentProblem& problem, const Parameters& params) {
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i)
    if (!problem.keyframes[i].fixed) problem.keyframes[i].T_cw = from_parameters(params.poses[i]);
  for (std::size_t i = 0; i < problem.points.size(); ++i)
    if (!problem.points[i].fixed) problem.points[i].position = params.points[i];
}

}  // namespace

BundleAdjustmentReport bundle_adjust(BundleAdjustmentProblem& problem,
                                     const BundleAdjusterOptions& options) {
  BundleAdjustmentReport report;
  report.outlier.assign(problem.observations.size(), false);
  if (problem.observations.empty()) return report;

  Parameters params = collect_parameters(problem);
  const std::vector<bool> none(problem.observations.size(), false);
  const ceres::Solver::Summary first =
      solve(problem, params, none, true, options.iterations, options);
  report.initial_cost = first.initial_cost;
  report.final_cost = first.final_cost;
  report.iterations = first.num_successful_steps + first.num_unsuccessful_steps;

  const bool aborted = options.abort && options.abort->load();
  if (options.refine_iterations > 0 && !aborted) {
    const std::vector<bool> skip = classify_outliers(problem, params);
    const ceres::Solver::Summary refined =
        solve(problem, params, skip, false, options.refine_iterations, options);
    const int refine_steps = refined.num_successful_steps + refined.num_unsuccessful_steps;
    if (refine_steps > 0) report.final_cost = refined.final_cost;
    report.iterations += refine_steps;
  }
  report.outlier = classify_outliers(problem, params);
  for (bool o : report.outlier) report.outliers += o ? 1 : 0;
  write_back(problem, params);
  report.solved = true;
  return report;
}

}  // namespace sbaslam::optimize
