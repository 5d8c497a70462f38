#include "sbaslam/core/camera.h"

#include <cmath>

namespace sbaslam {

PinholeCamera::PinholeCamera(const PinholeIntrinsics& intrinsics,
                             const RadTanDistortion& distortion)
    : k_(intrinsics), d_(distortion), has_distortion_(!distortion.is_zero()) {}

// Even a zero Kannala-Brandt distortion is the equidistant projection, not a pinhole one.
PinholeCamera::PinholeCamera(const PinholeIntrinsics& intrinsics,
                             const KannalaBrandtDistortion& fisheye)
    : k_(intrinsics), model_(CameraModel::kKannalaBrandt8), f_(fisheye), has_distortion_(true) {}

PinholeCamera::PinholeCamera(const CameraSettings& settings)
    : PinholeCamera(settings.model == CameraModel::kKannalaBrandt8
                        ? PinholeCamera(settings.intrinsics, settings.fisheye)
                        : PinholeCamera(settings.intrinsics, settings.distortion)) {}

double PinholeCamera::fisheye_radius(double theta) const {
  const double t2 = theta * theta;
  return theta * (1.0 + t2 * (f_.k1 + t2 * (f_.k2 + t2 * (f_.k3 + t2 * f_.k4))));
}

double PinholeCamera::fisheye_angle(double theta_d) const {
  // Newton's method from theta = theta_d; the polynomial is monotonic over any sane calibration's
  // field of view.
  double theta = theta_d;
  for (int it = 0; it < 20; ++it) {
    const double t2 = theta * theta;
    const double slope =
        1.0 + t2 * (3.0 * f_.k1 + t2 * (5.0 * f_.k2 + t2 * (7.0 * f_.k3 + t2 * 9.0 * f_.k4)));
    const double step = (fisheye_radius(theta) - theta_d) / slope;
    if (!std::isfinite(step)) break;
    theta -= step;
    if (std::abs(step) < 1e-14) break;
  }
  return theta;
}

double PinholeCamera::field_angle(const Vec2& uv_distorted) const {
  const Vec2 xy = normalized(uv_distorted);
  if (is_fisheye()) return fisheye_angle(xy.norm());
  return std::atan(normalized(undistort(uv_distorted)).norm());
}

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
  if (is_fisheye()) {
    const Vec2 xy = normalized(uv);
    const double r = xy.norm();
    // theta_d / r tends to 1 on the axis.
    const double scale = r > 1e-12 ? fisheye_radius(std::atan(r)) / r : 1.0;
    return {k_.fx * scale * xy.x() + k_.cx, k_.fy * scale * xy.y() + k_.cy};
  }
  const Vec2 xd = distort_normalized(normalized(uv), nullptr);
  return {k_.fx * xd.x() + k_.cx, k_.fy * xd.y() + k_.cy};
}

Vec2 PinholeCamera::undistort(const Vec2& uv_distorted) const {
  if (!has_distortion_) return uv_distorted;
  const Vec2 target = normalized(uv_distorted);
  if (is_fisheye()) {
    const double theta_d = target.norm();
    const double scale = theta_d > 1e-12 ? std::tan(fisheye_angle(theta_d)) / theta_d : 1.0;
    return {k_.fx * scale * target.x() + k_.cx, k_.fy * scale * target.y() + k_.cy};
  }
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

Vec2 PinholeCamera::undistort_within_field(const Vec2& uv_distorted) const {
  if (!is_fisheye()) return undistort(uv_distorted);
  const Vec2 xy = normalized(uv_distorted);
  const double theta_d = xy.norm();
  if (fisheye_angle(theta_d) <= kMaxFisheyeFieldAngle) return undistort(uv_distorted);
  const Vec2 on_limit = xy * (std::tan(kMaxFisheyeFieldAngle) / theta_d);
  return {k_.fx * on_limit.x() + k_.cx, k_.fy * on_limit.y() + k_.cy};
}

void PinholeCamera::undistort(std::vector<cv::Point2f>& points) const {
  if (!has_distortion_) return;
  for (cv::Point2f& p : points) {
    const Vec2 uv = undistort(Vec2(p.x, p.y));
    p = cv::Point2f(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
  }
}

cv::Mat PinholeCamera::dist_coeffs() const {
  if (is_fisheye()) return (cv::Mat_<double>(1, 4) << f_.k1, f_.k2, f_.k3, f_.k4);
  return (cv::Mat_<double>(1, 5) << d_.k1, d_.k2, d_.p1, d_.p2, d_.k3);
}

}  // namespace sbaslam
