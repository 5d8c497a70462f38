#include "sbaslam/core/lie.h"

#include <cmath>

namespace sbaslam {
namespace {

// Below this angle the closed forms divide by ~0, so their Taylor expansions are used instead.
constexpr double kSmallAngle = 1e-8;

// Left Jacobian of SO(3) (the "V" matrix of SE(3)).
Mat3 so3_left_jacobian(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = hat(phi);
  if (theta < 1e-5) return Mat3::Identity() + 0.5 * K + (1.0 / 6.0) * K * K;
  const double t2 = theta * theta;
  return Mat3::Identity() + ((1.0 - std::cos(theta)) / t2) * K +
         ((theta - std::sin(theta)) / (t2 * theta)) * K * K;
}

Mat3 so3_left_jacobian_inverse(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = hat(phi);
  if (theta < 1e-5) return Mat3::Identity() - 0.5 * K + (1.0 / 12.0) * K * K;
  const double coef =
      (1.0 - theta * std::sin(theta) / (2.0 * (1.0 - std::cos(theta)))) / (theta * theta);
  return Mat3::Identity() - 0.5 * K + coef * K * K;
}

// V = integral_0^1 exp(sigma s) exp(s hat(phi)) ds, which maps sim(3)'s rho to the translation.
Mat3 sim3_V(const Vec3& phi, double sigma) {
  const double theta = phi.norm();
  const Mat3 K = hat(phi);
  const double A = std::abs(sigma) < 1e-12 ? 1.0 : std::expm1(sigma) / sigma;
  double c1;  // coefficient of K
  double c2;  // coefficient of K^2
  if (theta < 1e-5) {
    // Limits theta -> 0: c1 = int e^{sigma s} s ds, c2 = int e^{sigma s} s^2 / 2 ds.
    if (std::abs(sigma) < 1e-4) {
      c1 = 0.5 + sigma / 3.0 + sigma * sigma / 8.0;
      c2 = 1.0 / 6.0 + sigma / 8.0 + sigma * sigma / 20.0;
    } else {
      const double es = std::exp(sigma);
      const double s2 = sigma * sigma;
      c1 = (es * (sigma - 1.0) + 1.0) / s2;
      c2 = 0.5 * (es * (s2 - 2.0 * sigma + 2.0) - 2.0) / (s2 * sigma);
    }
  } else {
    const double es = std::exp(sigma);
    const double d = sigma * sigma + theta * theta;
    const double S = (es * (sigma * std::sin(theta) - theta * std::cos(theta)) + theta) / d;
    const double C = (es * (sigma * std::cos(theta) + theta * std::sin(theta)) - sigma) / d;
    c1 = S / theta;
    c2 = (A - C) / (theta * theta);
  }
  return A * Mat3::Identity() + c1 * K + c2 * K * K;
}

}  // namespace

Mat3 hat(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Vec3 vee(const Mat3& m) {
  return Vec3(m(2, 1), m(0, 2), m(1, 0));
}

SO3::SO3(const Quat& q) : q_(q.normalized()) {}

SO3 SO3::from_matrix(const Mat3& R) {
  return SO3(Quat(R));
}

SO3 SO3::exp(const Vec3& phi) {
  const double theta = phi.norm();
  if (theta < kSmallAngle) {
    // First-order quaternion; normalisation in the constructor keeps it unit.
    return SO3(Quat(1.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()));
  }
  const Vec3 axis = phi / theta;
  const double half = 0.5 * theta;
  const Vec3 v = std::sin(half) * axis;
  return SO3(Quat(std::cos(half), v.x(), v.y(), v.z()));
}

Vec3 SO3::log() const {
  // q and -q are the same rotation; w >= 0 gives the angle in [0, pi].
  Quat q = q_;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vec3 v = q.vec();
  const double n = v.norm();
  if (n < kSmallAngle) return 2.0 * v / q.w();
  const double theta = 2.0 * std::atan2(n, q.w());
  return theta * v / n;
}

SE3 SE3::from_matrix(const Mat4& T) {
  return SE3(SO3::from_matrix(T.topLeftCorner<3, 3>()), T.topRightCorner<3, 1>());
}

SE3 SE3::from_matrix(const Mat34& T) {
  return SE3(SO3::from_matrix(T.leftCols<3>()), T.col(3));
}

SE3 SE3::exp(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  return SE3(SO3::exp(phi), so3_left_jacobian(phi) * rho);
}

Vec6 SE3::log() const {
  const Vec3 phi = R_.log();
  Vec6 xi;
  xi.head<3>() = so3_left_jacobian_inverse(phi) * t_;
  xi.tail<3>() = phi;
  return xi;
}

SE3 SE3::inverse() const {
  const SO3 Rinv = R_.inverse();
  return SE3(Rinv, -(Rinv * t_));
}

Mat4 SE3::matrix() const {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = R_.matrix();
  T.topRightCorner<3, 1>() = t_;
  return T;
}

Mat34 SE3::matrix3x4() const {
  Mat34 T;
  T.leftCols<3>() = R_.matrix();
  T.col(3) = t_;
  return T;
}

Sim3::Sim3(double scale, const SO3& R, const Vec3& t) : s_(scale), R_(R), t_(t) {}

Sim3 Sim3::from_matrix(const Mat4& T) {
  const Mat3 sR = T.topLeftCorner<3, 3>();
  const double s = std::cbrt(sR.determinant());
  return Sim3(s, SO3::from_matrix(sR / s), T.topRightCorner<3, 1>());
}

Sim3 Sim3::exp(const Vec7& zeta) {
  const Vec3 rho = zeta.head<3>();
  const Vec3 phi = zeta.segment<3>(3);
  const double sigma = zeta(6);
  return Sim3(std::exp(sigma), SO3::exp(phi), sim3_V(phi, sigma) * rho);
}

Vec7 Sim3::log() const {
  const Vec3 phi = R_.log();
  const double sigma = std::log(s_);
  Vec7 zeta;
  zeta.head<3>() = sim3_V(phi, sigma).lu().solve(t_);
  zeta.segment<3>(3) = phi;
  zeta(6) = sigma;
  return zeta;
}

Sim3 Sim3::inverse() const {
  const SO3 Rinv = R_.inverse();
  const double sinv = 1.0 / s_;
  return Sim3(sinv, Rinv, -sinv * (Rinv * t_));
}

Mat4 Sim3::matrix() const {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = s_ * R_.matrix();
  T.topRightCorner<3, 1>() = t_;
  return T;
}

Sim3 Sim3::operator*(const Sim3& other) const {
  return Sim3(s_ * other.s_, R_ * other.R_, s_ * (R_ * other.t_) + t_);
}

SE3 Sim3::operator*(const SE3& pose) const {
  return SE3(R_ * pose.so3(), (*this) * pose.translation());
}

SE3 interpolate(const SE3& a, const SE3& b, double alpha) {
  const Quat q = a.quaternion().slerp(alpha, b.quaternion());
  const Vec3 t = (1.0 - alpha) * a.translation() + alpha * b.translation();
  return SE3(q, t);
}

}  // namespace sbaslam
