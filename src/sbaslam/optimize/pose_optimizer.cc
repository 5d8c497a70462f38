#include "sbaslam/optimize/pose_optimizer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "sbaslam/optimize/pose_only_cost.h"
#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::optimize {
namespace {

// Ceres' defaults for its Levenberg-Marquardt trust region, which motion-only BA used before it
// had its own 6-dof solver: the same steps, stopping rules and radius updates.
constexpr double kInitialRadius = 1e4;
constexpr double kMaxRadius = 1e16;
constexpr double kMinRadius = 1e-32;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;

PoseParameters plus(const PoseParameters& x, const Vec6& step) {
  PoseParameters out;
  PoseManifold().Plus(x.data(), step.data(), out.data());
  return out;
}

double ambient_distance(const PoseParameters& a, const PoseParameters& b) {
  double d = 0.0;
  for (int i = 0; i < 7; ++i) d += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(d);
}

// Ceres' gradient test: how far a full gradient step moves the parameters (max norm).
bool gradient_vanishes(const PoseParameters& x, const Vec6& gradient) {
  const PoseParameters moved = plus(x, -gradient);
  double largest = 0.0;
  for (int i = 0; i < 7; ++i) largest = std::max(largest, std::abs(x[i] - moved[i]));
  return largest <= kGradientTolerance;
}

// The trust region of one round: the damping of the normal equations and its updates.
class TrustRegion {
 public:
  // (H + D / radius) step = -g with D = diag(H), clamped as Ceres does; false if not solvable.
  bool step(const PoseNormalEquations& at, Vec6& step, double& model_decrease) const {
    Mat66 damped = at.H;
    for (int i = 0; i < 6; ++i)
      damped(i, i) += std::clamp(at.H(i, i), kMinDiagonal, kMaxDiagonal) / radius_;
    const Eigen::LLT<Mat66> llt(damped);
    step = -llt.solve(at.g);
    model_decrease = -(at.g.dot(step) + 0.5 * step.dot(at.H * step));
    return llt.info() == Eigen::Success && step.allFinite() && model_decrease > 0.0;
  }
  // Grows the region by how well the model predicted the decrease.
  void accepted(double relative_decrease) {
    const double q = 2.0 * relative_decrease - 1.0;
    radius_ = std::min(kMaxRadius, radius_ / std::max(1.0 / 3.0, 1.0 - q * q * q));
    decrease_factor_ = 2.0;
  }
  // Shrinks it, faster after each rejection in a row; false once it has collapsed.
  bool rejected() {
    radius_ /= decrease_factor_;
    decrease_factor_ *= 2.0;
    return radius_ >= kMinRadius;
  }

 private:
  double radius_ = kInitialRadius;
  double decrease_factor_ = 2.0;
};

bool step_is_negligible(const PoseParameters& from, const PoseParameters& to) {
  double x_norm = 0.0;
  for (double v : from) x_norm += v * v;
  return ambient_distance(to, from) <=
         kParameterTolerance * (std::sqrt(x_norm) + kParameterTolerance);
}

// Solves one round: the observations not flagged in `outlier`, robust or not, from the current
// pose, until a Ceres stopping rule holds or the iterations run out.
void solve_round(const RectifiedCamera& cam, const PoseOptimizerOptions& options,
                 PoseParameters& pose, const std::vector<Vec3>& points,
                 const std::vector<PixelObservation>& observations,
                 const std::vector<bool>& outlier, bool robust) {
  std::vector<std::size_t> active;
  for (std::size_t i = 0; i < observations.size(); ++i)
    if (!outlier[i]) active.push_back(i);
  if (active.empty()) return;
  const PoseOnlyCost cost(cam, observations, points, std::move(active),
                          robust ? options.huber_mono : 0.0, robust ? options.huber_stereo : 0.0);
  PoseNormalEquations current = cost.normal_equations(pose.data());
  if (gradient_vanishes(pose, current.g)) return;
  TrustRegion region;
  for (int iteration = 0; iteration < options.iterations_per_round; ++iteration) {
    Vec6 step;
    double model_decrease = 0.0;
    if (!region.step(current, step, model_decrease)) {
      if (!region.rejected()) return;
      continue;
    }
    const PoseParameters candidate = plus(pose, step);
    if (step_is_negligible(pose, candidate)) return;
    // Nearly every step is taken, so the candidate's normal equations are summed with its cost in
    // one pass instead of a cost pass followed by another at the accepted pose.
    PoseNormalEquations at_candidate = cost.normal_equations(candidate.data());
    const double candidate_cost = at_candidate.cost;
    // As Ceres: a step that changes the cost too little ends the round without being taken.
    if (std::abs(current.cost - candidate_cost) <= kFunctionTolerance * current.cost) return;
    const double relative_decrease = (current.cost - candidate_cost) / model_decrease;
    // A point behind the camera has a zero residual, so a step that carries the camera past
    // points can lower the cost: such a step is rejected, as Ceres rejects a failed evaluation.
    if (!std::isfinite(candidate_cost) || relative_decrease <= kMinRelativeDecrease ||
        at_candidate.behind_camera > current.behind_camera) {
      if (!region.rejected()) return;
      continue;
    }
    pose = candidate;
    current = at_candidate;
    region.accepted(relative_decrease);
    if (gradient_vanishes(pose, current.g)) return;
  }
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
