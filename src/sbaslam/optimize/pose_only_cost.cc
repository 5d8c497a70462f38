#include "sbaslam/optimize/pose_only_cost.h"

#include <algorithm>
#include <cmath>

namespace sbaslam::optimize {

double huber_rho(double s, double delta) {
  if (s <= delta * delta) return s;
  return 2.0 * delta * std::sqrt(s) - delta * delta;
}

PoseOnlyCost::PoseOnlyCost(const RectifiedCamera& cam,
                           const std::vector<PixelObservation>& observations,
                           const std::vector<Vec3>& points, std::vector<std::size_t> active,
                           double huber_mono, double huber_stereo)
    : cam_(cam),
      observations_(observations),
      points_(points),
      active_(std::move(active)),
      huber_mono_(huber_mono),
      huber_stereo_(huber_stereo) {
  for (std::size_t i : active_) num_residuals_ += observations_[i].residual_size();
}

int PoseOnlyCost::robust_rows(std::size_t i, const double* pose, double* rows,
                              double* jacobian) const {
  const PixelObservation& obs = observations_[i];
  const int n = obs.residual_size();
  double e[3], J[21];
  evaluate_reprojection(cam_, obs, pose, points_[i].data(), e, jacobian ? J : nullptr, nullptr);
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
  for (int r = 0; r < n; ++r) rows[r] = g * e[r];
  if (!jacobian) return n;
  // d(g e)/dx = g J + e (dg/ds) (2 e^T J); the tangent is J's first 6 of 7 columns.
  double eJ[6] = {0, 0, 0, 0, 0, 0};
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 6; ++c) eJ[c] += e[r] * J[7 * r + c];
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 6; ++c) jacobian[6 * r + c] = g * J[7 * r + c] + two_dg_ds * e[r] * eJ[c];
  return n;
}

void PoseOnlyCost::evaluate(const double* pose, double* residuals, double* jacobian) const {
  for (std::size_t i : active_) {
    const int n = robust_rows(i, pose, residuals, jacobian);
    residuals += n;
    if (jacobian) jacobian += 6 * n;
  }
}

double PoseOnlyCost::cost(const double* pose) const {
  double sum = 0.0, rows[3];
  for (std::size_t i : active_) {
    const int n = robust_rows(i, pose, rows, nullptr);
    for (int r = 0; r < n; ++r) sum += rows[r] * rows[r];
  }
  return 0.5 * sum;
}

PoseNormalEquations PoseOnlyCost::normal_equations(const double* pose) const {
  PoseNormalEquations out;
  // Summed in a fixed-size row-major array; Eigen's 6x6 rank updates cost more per observation.
  double H[6][6] = {}, g[6] = {}, cost = 0.0;
  double rows[3], J[18];
  for (std::size_t i : active_) {
    const int n = robust_rows(i, pose, rows, J);
    for (int r = 0; r < n; ++r) {
      const double* Jr = J + 6 * r;
      cost += rows[r] * rows[r];
      for (int a = 0; a < 6; ++a) {
        g[a] += Jr[a] * rows[r];
        for (int b = a; b < 6; ++b) H[a][b] += Jr[a] * Jr[b];
      }
    }
  }
  out.cost = 0.5 * cost;
  for (int a = 0; a < 6; ++a) {
    out.g[a] = g[a];
    for (int b = a; b < 6; ++b) out.H(a, b) = out.H(b, a) = H[a][b];
  }
  return out;
}

}  // namespace sbaslam::optimize
