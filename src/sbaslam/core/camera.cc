#include "sbaslam/core/camera.h"

#include <cmath>

namespace sbaslam {

PinholeCamera::PinholeCamera(const PinholeIntrinsics& intrinsics,
                             const RadTanDistortion& distortion)
    : k_(intrinsics), d_(distortion), has_distortion_(!distortion.is_zero()) {}

Eigen::Matrix<double, 2, 3> PinholeCamera::project_jacobian(const Vec3& p_c) const {
  const double inv_z = 1.0 / p_c.z();
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix<double, 2, 3> J;
  J << k_.fx * inv_z, 0.0, -k_.fx * p_c.x() * inv_z2, 0.0, k_.fy * inv_z, -k_.fy * p_c.y() * inv_z2;
  return J;
}

Vec2 PinholeCamera::distort_normalized(const Vec2& xy, Eigen::Matrix2d* jacobian) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d_.k1 + r2 * (d_.k2 + r2 * d_.k3));
  const Vec2 out(x * radial + 2.0 * d_.p1 * x * y + d_.p2 * (r2 + 2.0 * x * x),
                 y * radial + d_.p1 * (r2 + 2.0 * y * y) + 2.0 * d_.p2 * x * y);
  if (jacobian) {
    // d(radial)/d(r2), then the chain rule through r2 = x^2 + y^2.
    const double dr = d_.k1 + r2 * (2.0 * d_.k2 + 3.0 * d_.k3 * r2);
    (*jacobian)(0, 0) = radial + 2.0 * x * x * dr + 2.0 * d_.p1 * y + 6.0 * d_.p2 * x;
    (*jacobian)(0, 1) = 2.0 * x * y * dr + 2.0 * d_.p1 * x + 2.0 * d_.p2 * y;
    (*jacobian)(1, 0) = 2.0 * x * y * dr + 2.0 * d_.p1 * x + 2.0 * d_.p2 * y;
    (*jacobian)(1, 1) = radial + 2.0 * y * y * dr + 6.0 * d_.p1 * y + 2.0 * d_.p2 * x;
  }
  return out;
}

Vec2 PinholeCamera::distort(const Vec2& uv) const {
  if (!has_distortion_) return uv;
  const Vec2 xd = distort_normalized(normalized(uv), nullptr);
  return {k_.fx * xd.x() + k_.cx, k_.fy * xd.y() + k_.cy};
}

Vec2 PinholeCamera::undistort(const Vec2& uv_distorted) const {
  if (!has_distortion_) return uv_distorted;
  const Vec2 target = normalized(uv_distorted);
  // Newton's method converges in a few steps inside the image, where distortion is a mild,
  // invertible warp. Far outside the valid field it may not; then OpenCV's fixed-point iteration
  // gives the same answer cv::undistortPoints would.
  Vec2 xy = target;
  Eigen::Matrix2d J;
  bool converged = false;
  for (int it = 0; it < 20; ++it) {
    const Vec2 residual = distort_normalized(xy, &J) - target;
    const Vec2 step = J.partialPivLu().solve(residual);
    if (!step.allFinite()) break;
    xy -= step;
    if (step.squaredNorm() < 1e-28) {
      converged = true;
      break;
    }
  }
  if (!converged || (distort_normalized(xy, nullptr) - target).norm() > 1e-12) {
    xy = target;
    for (int it = 0; it < 50; ++it) {
      const double x = xy.x(), y = xy.y();
      const double r2 = x * x + y * y;
      const double inv_radial = 1.0 / (1.0 + r2 * (d_.k1 + r2 * (d_.k2 + r2 * d_.k3)));
      const Vec2 tangential(2.0 * d_.p1 * x * y + d_.p2 * (r2 + 2.0 * x * x),
                            d_.p1 * (r2 + 2.0 * y * y) + 2.0 * d_.p2 * x * y);
      xy = (target - tangential) * inv_radial;
    }
  }
  return {k_.fx * xy.x() + k_.cx, k_.fy * xy.y() + k_.cy};
}

void PinholeCamera::undistort(std::vector<cv::Point2f>& points) const {
  if (!has_distortion_) return;
  for (cv::Point2f& p : points) {
    const Vec2 uv = undistort(Vec2(p.x, p.y));
    p = cv::Point2f(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
  }
}

cv::Mat PinholeCamera::dist_coeffs() const {
  return (cv::Mat_<double>(1, 5) << d_.k1, d_.k2, d_.p1, d_.p2, d_.k3);
}

}  // namespace sbaslam
