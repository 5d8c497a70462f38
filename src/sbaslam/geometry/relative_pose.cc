#include "sbaslam/geometry/relative_pose.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace sbaslam::geometry {

Mat3 camera_matrix(const PinholeIntrinsics& k) {
  Mat3 K;
  K << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0;
  return K;
}

namespace {

// Singular values closer than this ratio are treated as equal (ORB-SLAM's 1.00001).
constexpr double kEqualSingularValues = 1.00001;

bool same_motion(const RelativeMotion& a, const RelativeMotion& b) {
  return (a.R21 - b.R21).norm() < 1e-9 && (a.t21 - b.t21).norm() < 1e-9;
}

void add_unique(std::vector<RelativeMotion>& motions, const RelativeMotion& m) {
  for (const RelativeMotion& other : motions)
    if (same_motion(other, m)) return;
  motions.push_back(m);
}

}  // namespace

HomographyDecomposition decompose_homography(const Mat3& H21, const PinholeIntrinsics& k) {
  HomographyDecomposition out;
  const Mat3 K = camera_matrix(k);
  const Mat3 A = K.inverse() * H21 * K;
  Eigen::JacobiSVD<Mat3> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3 U = svd.matrixU(), V = svd.matrixV();
  const double s = U.determinant() * V.determinant();
  const double d1 = svd.singularValues()(0), d2 = svd.singularValues()(1);
  const double d3 = svd.singularValues()(2);
  if (d3 <= 0.0 || d1 / d3 < kEqualSingularValues) {
    out.pure_rotation = true;
    return out;
  }
  // With two equal singular values one of x1, x3 is exactly zero (the formulas' limit), which
  // makes candidates coincide; snapping keeps rounding from creating near-duplicates.
  double x1_abs = std::sqrt(std::max(0.0, (d1 * d1 - d2 * d2) / (d1 * d1 - d3 * d3)));
  double x3_abs = std::sqrt(std::max(0.0, (d2 * d2 - d3 * d3) / (d1 * d1 - d3 * d3)));
  if (d1 / d2 < kEqualSingularValues) x1_abs = 0.0;
  if (d2 / d3 < kEqualSingularValues) x3_abs = 0.0;
  const double x1[4] = {x1_abs, x1_abs, -x1_abs, -x1_abs};
  const double x3[4] = {x3_abs, -x3_abs, x3_abs, -x3_abs};

  const double root = std::sqrt(std::max(0.0, (d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3)));
  // Case d' = +d2.
  const double sin_theta = root / ((d1 + d3) * d2);
  const double cos_theta = (d2 * d2 + d1 * d3) / ((d1 + d3) * d2);
  const double sign_theta[4] = {1.0, -1.0, -1.0, 1.0};
  // Case d' = -d2.
  const double sin_phi = root / ((d1 - d3) * d2);
  const double cos_phi = (d1 * d3 - d2 * d2) / ((d1 - d3) * d2);

  auto finish = [&](const Mat3& Rp, const Vec3& tp, const Vec3& np) {
    RelativeMotion m;
    m.R21 = s * U * Rp * V.transpose();
    m.t21 = (U * tp).normalized();
    m.normal = V * np;
    if (m.normal.z() < 0.0) m.normal = -m.normal;
    add_unique(out.motions, m);
  };
  for (int i = 0; i < 4; ++i) {
    const double st = sign_theta[i] * sin_theta;
    Mat3 Rp;
    Rp << cos_theta, 0.0, -st, 0.0, 1.0, 0.0, st, 0.0, cos_theta;
    finish(Rp, Vec3(x1[i], 0.0, -x3[i]) * (d1 - d3), Vec3(x1[i], 0.0, x3[i]));
  }
  for (int i = 0; i < 4; ++i) {
    const double sp = sign_theta[i] * sin_phi;
    Mat3 Rp;
    Rp << cos_phi, 0.0, sp, 0.0, -1.0, 0.0, sp, 0.0, -cos_phi;
    finish(Rp, Vec3(x1[i], 0.0, x3[i]) * (d1 + d3), Vec3(x1[i], 0.0, x3[i]));
  }
  return out;
}

Mat3 essential_from_fundamental(const Mat3& F21, const PinholeIntrinsics& k) {
  const Mat3 K = camera_matrix(k);
  return K.transpose() * F21 * K;
}

std::vector<RelativeMotion> decompose_essential(const Mat3& E21) {
  Eigen::JacobiSVD<Mat3> svd(E21, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3 U = svd.matrixU(), V = svd.matrixV();
  const Vec3 t = U.col(2).normalized();
  Mat3 W;
  W << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  Mat3 R1 = U * W * V.transpose();
  if (R1.determinant() < 0.0) R1 = -R1;
  Mat3 R2 = U * W.transpose() * V.transpose();
  if (R2.determinant() < 0.0) R2 = -R2;
  return {
      {R1, t, Vec3::Zero()}, {R2, t, Vec3::Zero()}, {R1, -t, Vec3::Zero()}, {R2, -t, Vec3::Zero()}};
}

std::optional<Vec3> triangulate_linear(const Vec2& x1, const Vec2& x2, const Mat3& R21,
                                       const Vec3& t21) {
  Mat34 P1 = Mat34::Zero();
  P1.leftCols<3>().setIdentity();
  Mat34 P2;
  P2 << R21, t21;
  Mat4 A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  Eigen::JacobiSVD<Mat4> svd(A, Eigen::ComputeFullV);
  const Vec4 X = svd.matrixV().col(3);
  if (std::abs(X(3)) < 1e-12) return std::nullopt;
  const Vec3 p = X.head<3>() / X(3);
  if (!p.allFinite()) return std::nullopt;
  return p;
}

double rotation_angle_deg(const Mat3& Ra, const Mat3& Rb) {
  const double c = std::clamp(((Ra.transpose() * Rb).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

double direction_angle_deg(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace sbaslam::geometry
