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
      huber_stereo_(huber_stereo) {}

int PoseOnlyCost::residual(std::size_t i, const double* pose, double* e, double* jacobian,
                           double& delta, int& behind) const {
  const PixelObservation& obs = observations_[i];
  if (!evaluate_reprojection(cam_, obs, pose, points_[i].data(), e, jacobian, nullptr)) ++behind;
  delta = obs.is_stereo() ? huber_stereo_ : huber_mono_;
  return obs.residual_size();
}

PoseNormalEquations PoseOnlyCost::normal_equations(const double* pose) const {
  // Summed in a fixed-size row-major array; Eigen's 6x6 rank updates cost more per observation.
  double H[6][6] = {}, g[6] = {}, cost = 0.0;
  double e[3], J[21], delta = 0.0;
  int behind = 0;
  for (std::size_t i : active_) {
    const int n = residual(i, pose, e, J, delta, behind);
    double s = 0.0;
    for (int r = 0; r < n; ++r) s += e[r] * e[r];
    // rho'(s), and in the linear part the curvature term rho' * (-1 / s) J^T e e^T J.
    double rho1 = 1.0, along_e = 0.0;
    if (delta > 0.0 && s > delta * delta) {
      rho1 = delta / std::sqrt(s);
      along_e = rho1 / s;
      cost += huber_rho(s, delta);
    } else {
      cost += s;
    }
    double eJ[6] = {0, 0, 0, 0, 0, 0};
    for (int r = 0; r < n; ++r) {
      const double* Jr = J + 7 * r;  // the tangent is the first 6 of 7 columns
      for (int a = 0; a < 6; ++a) {
        eJ[a] += e[r] * Jr[a];
        for (int b = a; b < 6; ++b) H[a][b] += rho1 * Jr[a] * Jr[b];
      }
    }
    for (int a = 0; a < 6; ++a) {
      g[a] += rho1 * eJ[a];
      if (along_e > 0.0)
        for (int b = a; b < 6; ++b) H[a][b] -= along_e * eJ[a] * eJ[b];
    }
  }
  PoseNormalEquations out;
  out.cost = 0.5 * cost;
  out.behind_camera = behind;
  for (int a = 0; a < 6; ++a) {
    out.g[a] = g[a];
    for (int b = a; b < 6; ++b) out.H(a, b) = out.H(b, a) = H[a][b];
  }
  return out;
}

}  // namespace sbaslam::optimize
