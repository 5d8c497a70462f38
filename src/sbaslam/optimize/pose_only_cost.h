#pragma once
// Motion-only BA's cost in one Ceres residual block: every active observation of the frame, each
// under its own Huber kernel, applied inside the block. An observation with residual e (scaled by
// sqrt(w / sigma^2), see reprojection_cost.h) and s = |e|^2 contributes the rows
// e * sqrt(rho(s) / s), whose squared norm is rho(s): the objective is exactly ORB-SLAM's
// sum of rho(w e^T Sigma^-1 e). One block per observation, as local BA has, spent three quarters
// of motion-only BA's time in Ceres' per-block bookkeeping (bench: 6.4 ms for 900 stereo
// observations over 4 rounds).

#include <ceres/cost_function.h>

#include <vector>

#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

// Huber's rho(s) on a squared norm s, with threshold delta on the norm (Ceres' HuberLoss(delta)).
double huber_rho(double s, double delta);

class PoseOnlyBatchCost final : public ceres::CostFunction {
 public:
  // observations[i] sees points[i]; only the indices in `active` enter the cost. A threshold
  // <= 0 switches the kernel off (plain least squares).
  PoseOnlyBatchCost(const RectifiedCamera& cam, const std::vector<PixelObservation>& observations,
                    const std::vector<Vec3>& points, std::vector<std::size_t> active,
                    double huber_mono, double huber_stereo);

  // One parameter block: the pose [qx qy qz qw tx ty tz] (T_cw) with PoseManifold.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const RectifiedCamera& cam_;
  const std::vector<PixelObservation>& observations_;
  const std::vector<Vec3>& points_;
  std::vector<std::size_t> active_;
  double huber_mono_, huber_stereo_;
};

}  // namespace sbaslam::optimize
