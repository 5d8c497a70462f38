#include "sbaslam/optimize/pose_optimizer.h"

#include <ceres/ceres.h>

#include "sbaslam/optimize/pose_only_cost.h"
#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

// Solves one round: the observations not flagged in `outlier`, robust or not, from the current
// pose, in one residual block (see pose_only_cost.h).
void solve_round(const RectifiedCamera& cam, const PoseOptimizerOptions& options,
                 PoseParameters& pose, const std::vector<Vec3>& points,
                 const std::vector<PixelObservation>& observations,
                 const std::vector<bool>& outlier, bool robust) {
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < observations.size(); ++i)
    if (!outlier[i]) active.push_back(i);
  if (active.empty()) return;
  PoseOnlyBatchCost cost(cam, observations, points, std::move(active),
                         robust ? options.huber_mono : 0.0, robust ? options.huber_stereo : 0.0);
  const std::unique_ptr<ceres::Manifold> manifold = make_pose_manifold();
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(pose.data(), 7, manifold.get());
  problem.AddResidualBlock(&cost, nullptr, pose.data());

  ceres::Solver::Options solver;
  // The normal equations are 6x6: forming them beats a QR of the tall Jacobian.
  solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  // Same steps without the column scaling (bundle_adjuster.cc says why), ~5 % fewer instructions.
  solver.jacobi_scaling = false;
  solver.max_num_iterations = options.iterations_per_round;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
}

}  // namespace

PoseOptimizationResult PoseOptimizer::optimize(
    SE3& T_cw, const std::vector<Vec3>& points_world,
    const std::vector<PixelObservation>& observations) const {
  PoseOptimizationResult result;
  result.outlier.assign(observations.size(), false);
  result.inliers = static_cast<int>(observations.size());
  if (observations.size() < 3) return result;

  PoseParameters pose = to_parameters(T_cw);
  for (int round = 0; round < options_.rounds; ++round) {
    solve_round(camera_, options_, pose, points_world, observations, result.outlier,
                round < options_.robust_rounds);

    result.inliers = 0;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const ReprojectionCheck check =
          check_reprojection(camera_, pose.data(), points_world[i].data(), observations[i]);
      const double threshold = observations[i].is_stereo() ? kChi2Stereo : kChi2Mono;
      result.outlier[i] = !check.in_front || check.chi2 > threshold;
      if (!result.outlier[i]) ++result.inliers;
    }
    if (result.inliers < options_.min_observations) break;
  }
  T_cw = from_parameters(pose);
  return result;
}

}  // namespace sbaslam::optimize
