#include "sbaslam/optimize/pose_optimizer.h"

#include <ceres/ceres.h>

#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

// One Ceres problem serves all rounds: between rounds, outliers leave it and returning inliers
// re-enter it (fast removal), and the Huber kernels are switched off through their wrappers.
// Rebuilding the problem every round cost more than solving it.
class PoseProblem {
 public:
  PoseProblem(const RectifiedCamera& cam, const PoseOptimizerOptions& options, PoseParameters& pose,
              const std::vector<Vec3>& points, const std::vector<PixelObservation>& observations)
      : mono_loss_(new ceres::HuberLoss(options.huber_mono), ceres::TAKE_OWNERSHIP),
        stereo_loss_(new ceres::HuberLoss(options.huber_stereo), ceres::TAKE_OWNERSHIP),
        manifold_(make_pose_manifold()),
        problem_(problem_options()),
        pose_(pose.data()),
        observations_(observations),
        blocks_(observations.size(), nullptr) {
    costs_.reserve(observations.size());
    for (std::size_t i = 0; i < observations.size(); ++i)
      costs_.emplace_back(make_pose_only_reprojection_cost(cam, observations[i], points[i]));
    problem_.AddParameterBlock(pose_, 7, manifold_.get());
  }

  // Puts exactly the observations not flagged in `outlier` into the problem.
  void set_active(const std::vector<bool>& outlier) {
    for (std::size_t i = 0; i < observations_.size(); ++i) {
      if (outlier[i] && blocks_[i]) {
        problem_.RemoveResidualBlock(blocks_[i]);
        blocks_[i] = nullptr;
      } else if (!outlier[i] && !blocks_[i]) {
        ceres::LossFunction* loss = observations_[i].is_stereo() ? &stereo_loss_ : &mono_loss_;
        blocks_[i] = problem_.AddResidualBlock(costs_[i].get(), loss, pose_);
      }
    }
  }

  void solve(bool robust, int iterations) {
    if (!robust) {
      mono_loss_.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
      stereo_loss_.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
    }
    if (problem_.NumResidualBlocks() == 0) return;
    ceres::Solver::Options solver;
    // The normal equations are 6x6: forming them beats a QR of the tall Jacobian.
    solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver.max_num_iterations = iterations;
    solver.num_threads = 1;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem_, &summary);
  }

 private:
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    options.enable_fast_removal = true;
    return options;
  }

  // Declared before problem_, which refers to them without owning them: they are destroyed after
  // it.
  ceres::LossFunctionWrapper mono_loss_, stereo_loss_;
  std::unique_ptr<ceres::Manifold> manifold_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  ceres::Problem problem_;
  double* pose_;
  const std::vector<PixelObservation>& observations_;
  std::vector<ceres::ResidualBlockId> blocks_;
};

}  // namespace

PoseOptimizationResult PoseOptimizer::optimize(
    SE3& T_cw, const std::vector<Vec3>& points_world,
    const std::vector<PixelObservation>& observations) const {
  PoseOptimizationResult result;
  result.outlier.assign(observations.size(), false);
  result.inliers = static_cast<int>(observations.size());
  if (observations.size() < 3) return result;

  PoseParameters pose = to_parameters(T_cw);
  PoseProblem problem(camera_, options_, pose, points_world, observations);
  for (int round = 0; round < options_.rounds; ++round) {
    problem.set_active(result.outlier);
    problem.solve(round < options_.robust_rounds, options_.iterations_per_round);

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
