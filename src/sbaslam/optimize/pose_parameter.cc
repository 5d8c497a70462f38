#include "sbaslam/optimize/pose_parameter.h"

#include <algorithm>

namespace sbaslam::optimize {

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  RotationManifold().Plus(x, delta, x_plus_delta);
  for (int i = 0; i < 3; ++i) x_plus_delta[4 + i] = x[4 + i] + delta[3 + i];
  return true;
}

bool PoseManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  // Row-major 7 x 6: [I6; 0].
  std::fill(jacobian, jacobian + 42, 0.0);
  for (int i = 0; i < 6; ++i) jacobian[i * 6 + i] = 1.0;
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  RotationManifold().Minus(y, x, y_minus_x);
  for (int i = 0; i < 3; ++i) y_minus_x[3 + i] = y[4 + i] - x[4 + i];
  return true;
}

bool PoseManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  // Row-major 6 x 7: [I6 0], consistent with PlusJacobian.
  std::fill(jacobian, jacobian + 42, 0.0);
  for (int i = 0; i < 6; ++i) jacobian[i * 7 + i] = 1.0;
  return true;
}

bool RotationManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Quat> q(x);
  Eigen::Map<Quat> q_out(x_plus_delta);
  q_out = (SO3::exp(Vec3(delta[0], delta[1], delta[2])).quaternion() * q).normalized();
  return true;
}

bool RotationManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  // Row-major 4 x 3: [I3; 0], as PoseManifold's rotation rows.
  std::fill(jacobian, jacobian + 12, 0.0);
  for (int i = 0; i < 3; ++i) jacobian[i * 3 + i] = 1.0;
  return true;
}

bool RotationManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Quat> qy(y), qx(x);
  const Vec3 dphi = SO3(qy * qx.conjugate()).log();
  for (int i = 0; i < 3; ++i) y_minus_x[i] = dphi[i];
  return true;
}

bool RotationManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  // Row-major 3 x 4: [I3 0].
  std::fill(jacobian, jacobian + 12, 0.0);
  for (int i = 0; i < 3; ++i) jacobian[i * 4 + i] = 1.0;
  return true;
}

}  // namespace sbaslam::optimize
