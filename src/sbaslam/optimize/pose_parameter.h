#pragma once
// The 7-double pose block [qx qy qz qw tx ty tz] (T_cw) that Ceres optimises, and its manifold.
//
// The tangent is [dphi dt]: Plus rotates on the left, q' = exp(dphi) q, and adds dt to t. The
// analytic residuals (reprojection_factor.h) write their Jacobian with respect to this tangent into
// the first six columns of the 7-column ambient Jacobian (the seventh is zero), and PlusJacobian
// is [I6; 0], so Ceres' product J_ambient * PlusJacobian is exactly d residual / d tangent.

#include <ceres/manifold.h>

#include <array>
#include <memory>

#include "sbaslam/core/lie.h"

namespace sbaslam::optimize {

using PoseParameters = std::array<double, 7>;

inline PoseParameters to_parameters(const SE3& T) {
  const Quat& q = T.quaternion();
  const Vec3& t = T.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

inline SE3 from_parameters(const PoseParameters& p) {
  return SE3(Quat(p[3], p[0], p[1], p[2]), Vec3(p[4], p[5], p[6]));
}

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

inline std::unique_ptr<ceres::Manifold> make_pose_manifold() {
  return std::make_unique<PoseManifold>();
}

// The rotation part [qx qy qz qw] of a pose block as a block of its own, with the same left
// update q' = exp(dphi) q; the translation [tx ty tz] is then a plain 3-vector block. Local and
// global BA with stereo observations split every pose this way: with 3-dof pose blocks, 3-dof
// points and 3-row (stereo or padded) residuals, Ceres picks its compiled SchurEliminator<3, 3, 3>
// instead of the dynamic one it uses for 3-row residuals on 6-dof pose blocks. Monocular-only
// problems keep the 7-double block, for which <2, 3, 6> is compiled.
class RotationManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// Pointers into one PoseParameters: the rotation block and the translation block.
inline double* rotation_block(PoseParameters& p) {
  return p.data();
}
inline double* translation_block(PoseParameters& p) {
  return p.data() + 4;
}

}  // namespace sbaslam::optimize
