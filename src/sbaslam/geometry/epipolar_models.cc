#include "sbaslam/geometry/epipolar_models.h"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

namespace sbaslam::geometry {
namespace {

using DesignMatrix = Eigen::Matrix<double, Eigen::Dynamic, 9>;

// Right singular vector of the smallest singular value, as a row-major 3x3 matrix. The design
// matrix is padded with zero rows to at least 9 so that the full V always exists.
Mat3 null_vector(DesignMatrix& A) {
  if (A.rows() < 9) {
    const Eigen::Index filled = A.rows();
    A.conservativeResize(9, Eigen::NoChange);
    A.bottomRows(9 - filled).setZero();
  }
  Eigen::JacobiSVD<DesignMatrix> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  Mat3 M;
  M << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return M;
}

double transfer_error2(const Mat3& H, const Vec2& from, const Vec2& to) {
  const Vec3 mapped = H * Vec3(from.x(), from.y(), 1.0);
  if (std::abs(mapped.z()) < 1e-12) return std::numeric_limits<double>::infinity();
  return (mapped.hnormalized() - to).squaredNorm();
}

}  // namespace

Mat3 homography_dlt(const std::vector<Vec2>& p1, const std::vector<Vec2>& p2,
                    const std::vector<int>& indices) {
  DesignMatrix A(2 * indices.size(), 9);
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const double u1 = p1[indices[k]].x(), v1 = p1[indices[k]].y();
    const double u2 = p2[indices[k]].x(), v2 = p2[indices[k]].y();
    A.row(2 * k) << 0.0, 0.0, 0.0, -u1, -v1, -1.0, v2 * u1, v2 * v1, v2;
    A.row(2 * k + 1) << u1, v1, 1.0, 0.0, 0.0, 0.0, -u2 * u1, -u2 * v1, -u2;
  }
  return null_vector(A).normalized();
}

Mat3 fundamental_8point(const std::vector<Vec2>& p1, const std::vector<Vec2>& p2,
                        const std::vector<int>& indices) {
  DesignMatrix A(indices.size(), 9);
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const double u1 = p1[indices[k]].x(), v1 = p1[indices[k]].y();
    const double u2 = p2[indices[k]].x(), v2 = p2[indices[k]].y();
    A.row(k) << u2 * u1, u2 * v1, u2, v2 * u1, v2 * v1, v2, u1, v1, 1.0;
  }
  const Mat3 F = null_vector(A);
  // Nearest rank-2 matrix in the Frobenius norm: drop the smallest singular value.
  Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Vec3 s = svd.singularValues();
  s(2) = 0.0;
  return (svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose()).normalized();
}

ModelScore score_homography(const Mat3& H21, const Correspondences& c, double chi2_threshold) {
  ModelScore out;
  out.inliers.assign(c.size(), 0);
  const Eigen::FullPivLU<Mat3> lu(H21);
  if (!lu.isInvertible()) return out;
  const Mat3 H12 = lu.inverse();
  for (int i = 0; i < c.size(); ++i) {
    const double chi2_in_1 = transfer_error2(H12, c.p2[i], c.p1[i]) * c.inv_sigma2_1[i];
    const double chi2_in_2 = transfer_error2(H21, c.p1[i], c.p2[i]) * c.inv_sigma2_2[i];
    // As ORB-SLAM, each direction within the gate scores even when the other one fails.
    if (chi2_in_1 <= chi2_threshold) out.score += chi2_threshold - chi2_in_1;
    if (chi2_in_2 <= chi2_threshold) out.score += chi2_threshold - chi2_in_2;
    if (chi2_in_1 > chi2_threshold || chi2_in_2 > chi2_threshold) continue;
    out.inliers[i] = 1;
    ++out.inlier_count;
  }
  return out;
}

double epipolar_distance2(const Mat3& F21, const Vec2& x1, const Vec2& x2) {
  const Vec3 line = F21 * Vec3(x1.x(), x1.y(), 1.0);
  const double norm2 = line.x() * line.x() + line.y() * line.y();
  if (norm2 < 1e-30) return std::numeric_limits<double>::infinity();
  const double numerator = line.x() * x2.x() + line.y() * x2.y() + line.z();
  return numerator * numerator / norm2;
}

ModelScore score_fundamental(const Mat3& F21, const Correspondences& c, double chi2_threshold,
                             double score_threshold) {
  ModelScore out;
  out.inliers.assign(c.size(), 0);
  const Mat3 F12 = F21.transpose();
  for (int i = 0; i < c.size(); ++i) {
    const double chi2_in_2 = epipolar_distance2(F21, c.p1[i], c.p2[i]) * c.inv_sigma2_2[i];
    const double chi2_in_1 = epipolar_distance2(F12, c.p2[i], c.p1[i]) * c.inv_sigma2_1[i];
    if (chi2_in_1 <= chi2_threshold) out.score += score_threshold - chi2_in_1;
    if (chi2_in_2 <= chi2_threshold) out.score += score_threshold - chi2_in_2;
    if (chi2_in_1 > chi2_threshold || chi2_in_2 > chi2_threshold) continue;
    out.inliers[i] = 1;
    ++out.inlier_count;
  }
  return out;
}

}  // namespace sbaslam::geometry
