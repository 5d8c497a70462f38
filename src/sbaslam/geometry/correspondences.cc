#include "sbaslam/geometry/correspondences.h"

#include <cmath>

namespace sbaslam::geometry {

NormalizedPoints normalize_points(const std::vector<Vec2>& points) {
  NormalizedPoints out;
  const std::size_t n = points.size();
  if (n == 0) return out;
  Vec2 mean = Vec2::Zero();
  for (const Vec2& p : points) mean += p;
  mean /= static_cast<double>(n);
  Vec2 deviation = Vec2::Zero();
  out.points.reserve(n);
  for (const Vec2& p : points) {
    out.points.push_back(p - mean);
    deviation += (p - mean).cwiseAbs();
  }
  deviation /= static_cast<double>(n);
  // Coincident points have no spread: keep them unscaled rather than divide by zero.
  const double sx = deviation.x() > 0.0 ? 1.0 / deviation.x() : 1.0;
  const double sy = deviation.y() > 0.0 ? 1.0 / deviation.y() : 1.0;
  for (Vec2& p : out.points) p = Vec2(p.x() * sx, p.y() * sy);
  out.T << sx, 0.0, -mean.x() * sx, 0.0, sy, -mean.y() * sy, 0.0, 0.0, 1.0;
  return out;
}

}  // namespace sbaslam::geometry
