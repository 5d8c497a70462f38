#pragma once
// Synthetic multi-view geometry with a known answer, for optimiser and solver tests: points
// scattered in front of a row of cameras, and their exact projections.

#include <random>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::test {

inline optimize::RectifiedCamera kitti_like_camera() {
  return {718.856, 718.856, 607.1928, 185.2157, 386.1448};
}

// Camera i sits at x = i * spacing looking down +z (T_cw maps world into camera i).
inline std::vector<SE3> camera_row(int count, double spacing) {
  std::vector<SE3> poses;
  for (int i = 0; i < count; ++i)
    poses.push_back(SE3(SO3::exp(Vec3(0.0, 0.01 * i, 0.0)), Vec3(-spacing * i, 0.0, 0.0)));
  return poses;
}

inline std::vector<Vec3> random_points(int count, std::mt19937& rng) {
  std::uniform_real_distribution<double> x(-8.0, 8.0), y(-3.0, 3.0), z(4.0, 30.0);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  return points;
}

// The exact observation of a world point from pose T_cw; stereo when requested.
inline optimize::PixelObservation project(const optimize::RectifiedCamera& cam, const SE3& T_cw,
                                          const Vec3& point, bool stereo) {
  const Vec3 p = T_cw * point;
  optimize::PixelObservation obs;
  obs.u = cam.fx * p.x() / p.z() + cam.cx;
  obs.v = cam.fy * p.y() / p.z() + cam.cy;
  obs.u_right = stereo ? obs.u - cam.bf / p.z() : -1.0;
  return obs;
}

inline double rotation_error_deg(const SE3& a, const SE3& b) {
  return (a.so3().inverse() * b.so3()).angle() * 180.0 / M_PI;
}

}  // namespace sbaslam::test
