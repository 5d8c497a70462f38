#pragma once
// Lie groups SO(3), SE(3) and Sim(3) on Eigen, double precision.
// Tangent vectors are ordered [translation part, rotation part(, log scale)] as in Sophus:
//   se(3): [rho(3), phi(3)],  sim(3): [rho(3), phi(3), sigma].
// Group action on points: SO3: R x; SE3: R x + t; Sim3: s R x + t.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace sbaslam {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Quat = Eigen::Quaterniond;

Mat3 hat(const Vec3& v);
Vec3 vee(const Mat3& m);

class SO3 {
 public:
  SO3() : q_(Quat::Identity()) {}
  // The quaternion is normalised; its sign is kept.
  explicit SO3(const Quat& q);
  // Keeps q bit for bit (normalising again may change the last bits): for a quaternion that
  // quaternion() gave, e.g. one read back from a file.
  static SO3 from_unit_quaternion(const Quat& q) {
    SO3 R;
    R.q_ = q;
    return R;
  }
  // Projects a nearly orthonormal matrix onto SO(3) (through the nearest quaternion).
  static SO3 from_matrix(const Mat3& R);
  static SO3 exp(const Vec3& phi);

  Vec3 log() const;
  SO3 inverse() const { return SO3(q_.conjugate()); }
  Mat3 matrix() const { return q_.toRotationMatrix(); }
  const Quat& quaternion() const { return q_; }
  // Rotation angle in radians, in [0, pi].
  double angle() const { return log().norm(); }

  SO3 operator*(const SO3& other) const { return SO3(q_ * other.q_); }
  Vec3 operator*(const Vec3& p) const { return q_ * p; }

 private:
  Quat q_;
};

class SE3 {
 public:
  SE3() : t_(Vec3::Zero()) {}
  SE3(const SO3& R, const Vec3& t) : R_(R), t_(t) {}
  SE3(const Quat& q, const Vec3& t) : R_(q), t_(t) {}
  static SE3 from_matrix(const Mat4& T);
  static SE3 from_matrix(const Mat34& T);
  static SE3 exp(const Vec6& xi);

  Vec6 log() const;
  SE3 inverse() const;
  Mat4 matrix() const;
  Mat34 matrix3x4() const;
  const SO3& so3() const { return R_; }
  Mat3 rotation() const { return R_.matrix(); }
  const Vec3& translation() const { return t_; }
  Vec3& translation() { return t_; }
  const Quat& quaternion() const { return R_.quaternion(); }

  SE3 operator*(const SE3& other) const { return SE3(R_ * other.R_, R_ * other.t_ + t_); }
  Vec3 operator*(const Vec3& p) const { return R_ * p + t_; }

 private:
  SO3 R_;
  Vec3 t_;
};

class Sim3 {
 public:
  Sim3() : s_(1.0), t_(Vec3::Zero()) {}
  Sim3(double scale, const SO3& R, const Vec3& t);
  explicit Sim3(const SE3& T) : s_(1.0), R_(T.so3()), t_(T.translation()) {}
  static Sim3 from_matrix(const Mat4& T);
  static Sim3 exp(const Vec7& zeta);

  Vec7 log() const;
  Sim3 inverse() const;
  Mat4 matrix() const;
  double scale() const { return s_; }
  const SO3& so3() const { return R_; }
  Mat3 rotation() const { return R_.matrix(); }
  const Vec3& translation() const { return t_; }

  Sim3 operator*(const Sim3& other) const;
  Vec3 operator*(const Vec3& p) const { return s_ * (R_ * p) + t_; }
  // Applies this similarity to a rigid pose (pose maps body to world): the result keeps a unit
  // scale, its rotation is R * pose.R and its position is s R pose.t + t.
  SE3 operator*(const SE3& pose) const;

 private:
  double s_;
  SO3 R_;
  Vec3 t_;
};

// Interpolation for timestamps: slerp of the rotation and linear interpolation of the position,
// alpha in [0, 1] from a to b.
SE3 interpolate(const SE3& a, const SE3& b, double alpha);

}  // namespace sbaslam
