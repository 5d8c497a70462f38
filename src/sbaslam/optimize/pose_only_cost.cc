#include "sbaslam/optimize/pose_only_cost.h"

#include <algorithm>
#include <cmath>

namespace sbaslam::optimize {

double huber_rho(double s, double delta) {
  if (s <= delta * delta) return s;
  return 2.0 * delta * std::sqrt(s) - delta * delta;
}

PoseOnlyBatchCost::PoseOnlyBatchCost(const RectifiedCamera& cam,
                                     const std::vector<PixelObservation>& observations,
                                     const std::vector<Vec3>& points,
                                     std::vector<std::size_t> active, double huber_mono,
                                     double huber_stereo)
    : cam_(cam),
      observations_(observations),
      points_(points),
      active_(std::move(active)),
      huber_mono_(huber_mono),
      huber_stereo_(huber_stereo) {
  int rows = 0;
  for (std::size_t i : active_) rows += observations_[i].residual_size();
  set_num_residuals(rows);
  mutable_parameter_block_sizes()->push_back(7);
}

bool PoseOnlyBatchCost::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  double* jacobian = jacobians ? jacobians[0] : nullptr;
  double e[3], J[21];
  for (std::size_t i : active_) {
    const PixelObservation& obs = observations_[i];
    const int n = obs.residual_size();
    evaluate_reprojection(cam_, obs, parameters[0], points_[i].data(), e, jacobian ? J : nullptr,
                          nullptr);
    const double delta = obs.is_stereo() ? huber_stereo_ : huber_mono_;
    double s = 0.0;
    for (int r = 0; r < n; ++r) s += e[r] * e[r];
    // Inside the kernel's quadratic part (or without a kernel) the rows are e itself.
    double g = 1.0, two_dg_ds = 0.0;
    if (delta > 0.0 && s > delta * delta) {
      const double rho = huber_rho(s, delta);
      g = std::sqrt(rho / s);
      // d/ds sqrt(rho/s) = (rho'(s) s - rho) / (2 g s^2), rho'(s) = delta / sqrt(s).
      two_dg_ds = (delta * std::sqrt(s) - rho) / (g * s * s);
    }
    for (int r = 0; r < n; ++r) residuals[r] = g * e[r];
    if (jacobian) {
      // d(g e)/dx = g J + e (dg/ds) (2 e^T J).
      double eJ[7] = {0, 0, 0, 0, 0, 0, 0};
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < 7; ++c) eJ[c] += e[r] * J[7 * r + c];
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < 7; ++c)
          jacobian[7 * r + c] = g * J[7 * r + c] + two_dg_ds * e[r] * eJ[c];
      jacobian += 7 * n;
    }
    residuals += n;
  }
  return true;
}

}  // namespace sbaslam::optimize
