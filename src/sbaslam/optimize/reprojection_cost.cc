#include "sbaslam/optimize/reprojection_cost.h"

#include <algorithm>

namespace sbaslam::optimize {
namespace {

Vec3 to_camera(const double* pose, const double* point) {
  const Eigen::Map<const Quat> q(pose);
  return q * Vec3(point[0], point[1], point[2]) + Vec3(pose[4], pose[5], pose[6]);
}

}  // namespace

bool evaluate_reprojection(const RectifiedCamera& cam, const PixelObservation& obs,
                           const double* pose, const double* point, double* residual,
                           double* jacobian_pose, double* jacobian_point) {
  const int n = obs.residual_size();
  const Vec3 p = to_camera(pose, point);
  const double scale = residual_scale(obs);
  // A point behind the camera keeps a finite, zero-gradient residual; outlier checks remove it.
  if (p.z() <= 1e-9) {
    std::fill(residual, residual + n, 0.0);
    if (jacobian_pose) std::fill(jacobian_pose, jacobian_pose + 7 * n, 0.0);
    if (jacobian_point) std::fill(jacobian_point, jacobian_point + 3 * n, 0.0);
    return false;
  }
  const double inv_z = 1.0 / p.z();
  const double u = cam.fx * p.x() * inv_z + cam.cx;
  const double v = cam.fy * p.y() * inv_z + cam.cy;
  residual[0] = scale * (obs.u - u);
  residual[1] = scale * (obs.v - v);
  if (n == 3) residual[2] = scale * (obs.u_right - (u - cam.bf * inv_z));
  if (!jacobian_pose && !jacobian_point) return true;

  // d residual / d p_c (the residual is observation minus projection, hence the sign).
  Eigen::Matrix<double, 3, 3> J_p = Eigen::Matrix<double, 3, 3>::Zero();
  const double inv_z2 = inv_z * inv_z;
  J_p(0, 0) = -scale * cam.fx * inv_z;
  J_p(0, 2) = scale * cam.fx * p.x() * inv_z2;
  J_p(1, 1) = -scale * cam.fy * inv_z;
  J_p(1, 2) = scale * cam.fy * p.y() * inv_z2;
  J_p(2, 0) = J_p(0, 0);
  J_p(2, 2) = J_p(0, 2) - scale * cam.bf * inv_z2;

  if (jacobian_pose) {
    // p_c = exp(dphi) R X + t + dt: d p_c / d dphi = -hat(R X), d p_c / d dt = I.
    const Vec3 RX = p - Vec3(pose[4], pose[5], pose[6]);
    const Mat3 J_rot = -J_p * hat(RX);
    for (int r = 0; r < n; ++r) {
      double* row = jacobian_pose + 7 * r;
      for (int c = 0; c < 3; ++c) {
        row[c] = J_rot(r, c);
        row[3 + c] = J_p(r, c);
      }
      row[6] = 0.0;
    }
  }
  if (jacobian_point) {
    const Mat3 J_X = J_p * Eigen::Map<const Quat>(pose).toRotationMatrix();
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < 3; ++c) jacobian_point[3 * r + c] = J_X(r, c);
  }
  return true;
}

bool SplitPoseReprojectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  const double* q = parameters[0];
  const double* t = parameters[1];
  const double pose[7] = {q[0], q[1], q[2], q[3], t[0], t[1], t[2]};
  const bool want_pose = jacobians && (jacobians[0] || jacobians[1]);
  double J_pose[21];
  evaluate_reprojection(cam_, obs_, pose, parameters[2], residuals, want_pose ? J_pose : nullptr,
                        jacobians ? jacobians[2] : nullptr);
  const int n = obs_.residual_size();
  if (n == 2) residuals[2] = 0.0;
  if (!jacobians) return true;
  for (int r = 0; r < 3; ++r) {
    const bool padding = r >= n;
    if (jacobians[0]) {
      for (int c = 0; c < 3; ++c) jacobians[0][4 * r + c] = padding ? 0.0 : J_pose[7 * r + c];
      jacobians[0][4 * r + 3] = 0.0;
    }
    if (jacobians[1])
      for (int c = 0; c < 3; ++c) jacobians[1][3 * r + c] = padding ? 0.0 : J_pose[7 * r + 3 + c];
    if (jacobians[2] && padding)
      for (int c = 0; c < 3; ++c) jacobians[2][3 * r + c] = 0.0;
  }
  return true;
}

ReprojectionCheck check_reprojection(const RectifiedCamera& cam, const double* pose_qt,
                                     const double* point, const PixelObservation& obs) {
  const Vec3 p = to_camera(pose_qt, point);
  ReprojectionCheck check;
  check.in_front = p.z() > 0.0;
  if (!check.in_front) return check;
  const double u = cam.fx * p.x() / p.z() + cam.cx;
  const double v = cam.fy * p.y() / p.z() + cam.cy;
  const double du = obs.u - u;
  const double dv = obs.v - v;
  double sq = du * du + dv * dv;
  if (obs.is_stereo()) {
    const double dr = obs.u_right - (u - cam.bf / p.z());
    sq += dr * dr;
  }
  check.chi2 = sq * obs.inv_sigma2;
  return check;
}

}  // namespace sbaslam::optimize
