#include "sbaslam/optimize/bundle_adjuster.h"

#include <ceres/ceres.h>

#include <cstdlib>
#include <deque>
#include <memory>
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

// The Ceres problem of one bundle adjustment, built once for both passes: the refinement pass
// removes the first pass's outliers and, unless told to keep them, switches the Huber kernels off.
// Cost functions and losses live here, not in Ceres: with one heap object and one ownership count
// per observation, building and destroying the problem twice had cost as much as the solver's
// iterations (docs/RESULTS.md, "Session 10: local BA without the problem's overhead").
class CeresBundleProblem {
 public:
  CeresBundleProblem(const BundleAdjustmentProblem& problem, Parameters& params,
                     const BundleAdjusterOptions& options)
      : problem_(problem),
        options_(options),
        mono_loss_(new ceres::HuberLoss(options.huber_mono), ceres::TAKE_OWNERSHIP),
        stereo_loss_(new ceres::HuberLoss(options.huber_stereo), ceres::TAKE_OWNERSHIP),
        ceres_problem_(problem_options()) {
    for (const BaObservation& o : problem.observations)
      split_pose_ = split_pose_ || o.pixel.is_stereo();
    add_parameter_blocks(params);
    residuals_.reserve(problem.observations.size());
    for (const BaObservation& o : problem.observations) add_residual(o, params);
  }

  ceres::Solver::Summary solve(int iterations) {
    ceres::Solver::Options solver;
    if (free_keyframes_ == 0) {
      // Only points move: the normal equations are block diagonal, no Schur complement to form.
      solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    } else {
      solver.linear_solver_type = free_keyframes_ > options_.dense_schur_max_keyframes
                                      ? ceres::SPARSE_SCHUR
                                      : ceres::DENSE_SCHUR;
      solver.linear_solver_ordering = ordering_;
    }
    // Ceres' Levenberg-Marquardt damps with diag(J^T J) either way, so scaling the Jacobian's
    // columns to unit norm gives the same steps (trajectories equal to 1e-9) for ~4 % of the
    // instructions (docs/RESULTS.md, "Session 13").
    solver.jacobi_scaling = false;
    solver.max_num_iterations = iterations;
    solver.function_tolerance = options_.function_tolerance;
    solver.num_threads = options_.num_threads;
    solver.logging_type = ceres::SILENT;
    AbortCallback abort_callback(options_.abort);
    if (options_.abort) solver.callbacks.push_back(&abort_callback);
    ceres::Solver::Summary summary;
    if (ceres_problem_.NumResidualBlocks() > 0) ceres::Solve(solver, &ceres_problem_, &summary);
    return summary;
  }

  // The refinement pass: without the flagged observations, and without the robust kernel unless
  // options.refine_with_kernel.
  void prepare_refinement(const std::vector<bool>& outlier) {
    for (std::size_t i = 0; i < outlier.size(); ++i)
      if (outlier[i]) ceres_problem_.RemoveResidualBlock(residuals_[i]);
    if (options_.refine_with_kernel) return;
    mono_loss_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
    stereo_loss_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
  }

 private:
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    // Every block is added once, before its residuals, and a residual's three blocks are distinct
    // arrays: the checks Ceres would run cost a quarter of building the problem.
    options.disable_all_safety_checks = true;
    return options;
  }

  // With stereo observations the pose is two blocks (reprojection_cost.h says why).
  void add_parameter_blocks(Parameters& params) {
    ordering_ = std::make_shared<ceres::ParameterBlockOrdering>();
    std::vector<bool> observed_keyframe(problem_.keyframes.size(), false);
    std::vector<bool> observed_point(problem_.points.size(), false);
    for (const BaObservation& o : problem_.observations) {
      observed_keyframe[static_cast<std::size_t>(o.keyframe)] = true;
      observed_point[static_cast<std::size_t>(o.point)] = true;
    }
    for (std::size_t kf = 0; kf < problem_.keyframes.size(); ++kf) {
      if (!observed_keyframe[kf]) continue;
      std::vector<double*> blocks = {params.poses[kf].data()};
      if (split_pose_) {
        blocks = {rotation_block(params.poses[kf]), translation_block(params.poses[kf])};
        ceres_problem_.AddParameterBlock(blocks[0], 4, &rotation_manifold_);
        ceres_problem_.AddParameterBlock(blocks[1], 3);
      } else {
        ceres_problem_.AddParameterBlock(blocks[0], 7, &pose_manifold_);
      }
      for (double* block : blocks) {
        if (problem_.keyframes[kf].fixed) ceres_problem_.SetParameterBlockConstant(block);
        ordering_->AddElementToGroup(block, 1);
      }
      if (!problem_.keyframes[kf].fixed) ++free_keyframes_;
    }
    for (std::size_t pt = 0; pt < problem_.points.size(); ++pt) {
      if (!observed_point[pt]) continue;
      double* point = params.points[pt].data();
      ceres_problem_.AddParameterBlock(point, 3);
      if (problem_.points[pt].fixed) ceres_problem_.SetParameterBlockConstant(point);
      ordering_->AddElementToGroup(point, 0);
    }
  }

  void add_residual(const BaObservation& o, Parameters& params) {
    PoseParameters& pose = params.poses[static_cast<std::size_t>(o.keyframe)];
    double* point = params.points[static_cast<std::size_t>(o.point)].data();
    ceres::LossFunction* loss = o.pixel.is_stereo() ? &stereo_loss_ : &mono_loss_;
    PixelObservation pixel = o.pixel;
    pixel.weight *= options_.weight_scale;
    if (split_pose_) {
      ceres::CostFunction* cost = &split_costs_.emplace_back(problem_.camera, pixel);
      residuals_.push_back(ceres_problem_.AddResidualBlock(cost, loss, rotation_block(pose),
                                                           translation_block(pose), point));
    } else {
      ceres::CostFunction* cost = &mono_costs_.emplace_back(problem_.camera, pixel);
      residuals_.push_back(ceres_problem_.AddResidualBlock(cost, loss, pose.data(), point));
    }
  }

  const BundleAdjustmentProblem& problem_;
  const BundleAdjusterOptions& options_;
  // Declared before the problem, so they outlive it.
  PoseManifold pose_manifold_;
  RotationManifold rotation_manifold_;
  std::deque<SplitPoseReprojectionFactor> split_costs_;  // deque: the factors cannot move
  std::deque<MonoReprojectionFactor> mono_costs_;
  ceres::LossFunctionWrapper mono_loss_;
  ceres::LossFunctionWrapper stereo_loss_;
  ceres::Problem ceres_problem_;
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering_;
  std::vector<ceres::ResidualBlockId> residuals_;  // per observation
  bool split_pose_ = false;
  int free_keyframes_ = 0;
};

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
  CeresBundleProblem ceres_problem(problem, params, options);
  const ceres::Solver::Summary first = ceres_problem.solve(options.iterations);
  report.initial_cost = first.initial_cost;
  report.final_cost = first.final_cost;
  report.iterations = first.num_successful_steps + first.num_unsuccessful_steps;

  const bool aborted = options.abort && options.abort->load();
  if (options.refine_iterations > 0 && !aborted) {
    ceres_problem.prepare_refinement(classify_outliers(problem, params));
    const ceres::Solver::Summary refined = ceres_problem.solve(options.refine_iterations);
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
