#pragma once
// Motion-only BA's cost: every active observation of the frame, each under its own Huber kernel.
// An observation with residual e (scaled by sqrt(w / sigma^2), see reprojection_cost.h) and
// s = |e|^2 contributes the rows e * sqrt(rho(s) / s), whose squared norm is rho(s): the objective
// is exactly ORB-SLAM's sum of rho(w e^T Sigma^-1 e). The Jacobian of those rows is exact (not
// the iteratively reweighted approximation), as Ceres' solver saw it when this cost was a Ceres
// residual block.
//
// The 6-dof solver (pose_optimizer.cc) needs only J^T J and J^T r, so normal_equations() sums
// them per observation in one pass. Through Ceres, the tall Jacobian, its validity checks and its
// product took more than half of motion-only BA's time (bench: 1.52 ms for 900 stereo
// observations over 4 rounds).

#include <Eigen/Core>
#include <vector>

#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

using Mat66 = Eigen::Matrix<double, 6, 6>;

// Huber's rho(s) on a squared norm s, with threshold delta on the norm (Ceres' HuberLoss(delta)).
double huber_rho(double s, double delta);

// The Gauss-Newton normal equations of the cost at one pose: cost = 1/2 sum rho, H = J^T J,
// g = J^T r, with J taken with respect to the pose tangent [dphi dt] (pose_parameter.h).
struct PoseNormalEquations {
  double cost = 0.0;
  Mat66 H = Mat66::Zero();
  Vec6 g = Vec6::Zero();
};

class PoseOnlyCost {
 public:
  // observations[i] sees points[i]; only the indices in `active` enter the cost. A threshold
  // <= 0 switches the kernel off (plain least squares). The vectors are referenced, not copied.
  PoseOnlyCost(const RectifiedCamera& cam, const std::vector<PixelObservation>& observations,
               const std::vector<Vec3>& points, std::vector<std::size_t> active, double huber_mono,
               double huber_stereo);

  int num_residuals() const { return num_residuals_; }

  // The rows and, when `jacobian` is given, their Jacobian (row-major, num_residuals() x 6) at
  // the pose [qx qy qz qw tx ty tz].
  void evaluate(const double* pose, double* residuals, double* jacobian) const;

  // 1/2 sum rho alone, without the Jacobian.
  double cost(const double* pose) const;

  PoseNormalEquations normal_equations(const double* pose) const;

 private:
  // One observation's rows (n = 2 or 3) and, if `jacobian` is given, their n x 6 Jacobian.
  int robust_rows(std::size_t i, const double* pose, double* rows, double* jacobian) const;

  const RectifiedCamera& cam_;
  const std::vector<PixelObservation>& observations_;
  const std::vector<Vec3>& points_;
  std::vector<std::size_t> active_;
  double huber_mono_, huber_stereo_;
  int num_residuals_ = 0;
};

}  // namespace sbaslam::optimize
