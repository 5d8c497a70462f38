#include "sbaslam/geometry/motion_check.h"

#include <algorithm>
#include <cmath>

namespace sbaslam::geometry {
namespace {

Vec2 to_normalized(const Vec2& uv, const PinholeIntrinsics& k) {
  return {(uv.x() - k.cx) / k.fx, (uv.y() - k.cy) / k.fy};
}

Vec2 to_pixel(const Vec3& p, const PinholeIntrinsics& k) {
  return {k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy};
}

double angle_deg_of_cos(double c) {
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

MotionSupport check_motion(const RelativeMotion& motion, const Correspondences& c,
                           const std::vector<char>& inliers, const PinholeIntrinsics& k,
                           const MotionCheckOptions& options) {
  MotionSupport out;
  out.points.assign(c.size(), Vec3::Zero());
  out.valid.assign(c.size(), 0);
  const Vec3 center2 = -motion.R21.transpose() * motion.t21;  // camera 2's centre in camera 1
  std::vector<double> cos_parallax;
  for (int i = 0; i < c.size(); ++i) {
    if (!inliers[i]) continue;
    const auto point = triangulate_linear(to_normalized(c.p1[i], k), to_normalized(c.p2[i], k),
                                          motion.R21, motion.t21);
    if (!point) continue;
    const Vec3& X1 = *point;
    const Vec3 ray1 = X1, ray2 = X1 - center2;
    const double cos_p = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
    const bool has_parallax = cos_p < options.parallel_cos;
    const Vec3 X2 = motion.R21 * X1 + motion.t21;
    if (has_parallax && (X1.z() <= 0.0 || X2.z() <= 0.0)) continue;
    // Written as !(chi2 <= gate) so that a point on a camera plane (NaN pixel) fails too.
    if (!((to_pixel(X1, k) - c.p1[i]).squaredNorm() * c.inv_sigma2_1[i] <=
          options.reprojection_chi2))
      continue;
    if (!((to_pixel(X2, k) - c.p2[i]).squaredNorm() * c.inv_sigma2_2[i] <=
          options.reprojection_chi2))
      continue;
    cos_parallax.push_back(cos_p);
    ++out.good;
    out.points[i] = X1;
    if (has_parallax) {
      out.valid[i] = 1;
      ++out.triangulated;
    }
  }
  if (cos_parallax.empty()) return out;
  std::sort(cos_parallax.begin(), cos_parallax.end());  // largest parallax first
  const std::size_t rank = std::min(static_cast<std::size_t>(std::max(options.parallax_rank, 0)),
                                    cos_parallax.size() - 1);
  out.parallax_deg = angle_deg_of_cos(cos_parallax[rank]);
  out.median_parallax_deg = angle_deg_of_cos(cos_parallax[cos_parallax.size() / 2]);
  return out;
}

}  // namespace sbaslam::geometry
