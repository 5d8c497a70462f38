#include "sbaslam/optimize/pose_optimizer.h"

#include <ceres/ceres.h>

#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

void solve_round(const RectifiedCamera& cam, const PoseOptimizerOptions& options, bool robust,
                 PoseParameters& pose, const std::vector<Vec3>& points,
                 const std::vector<PixelObservation>& observations,
                 const std::vector<bool>& outlier) {
  ceres::Problem problem;
  problem.AddParameterBlock(pose.data(), 7, make_pose_manifold().release());
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (outlier[i]) continue;
    const PixelObservation& obs = observations[i];
    ceres::LossFunction* loss = nullptr;
    if (robust)
      loss = new ceres::HuberLoss(obs.is_stereo() ? options.huber_stereo : options.huber_mono);
    problem.AddResidualBlock(make_pose_only_reprojection_cost(cam, obs, points[i]), loss,
                             pose.data());
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
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
    const bool robust = round < options_.robust_rounds;
    solve_round(camera_, options_, robust, pose, points_world, observations, result.outlier);

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
