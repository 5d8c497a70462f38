#pragma once
// Synthetic two-view problems with a known answer: points (in a box, or on a plane) seen by two
// pinhole cameras, with Gaussian pixel noise and a share of outlier matches.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/geometry/correspondences.h"
#include "sbaslam/geometry/relative_pose.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::test {

inline PinholeIntrinsics vga_intrinsics() {
  return {520.0, 520.0, 320.0, 240.0};
}

struct TwoViewScene {
  PinholeIntrinsics k = vga_intrinsics();
  Mat3 R21 = Mat3::Identity();
  Vec3 t21 = Vec3::Zero();    // metric
  std::vector<Vec3> points1;  // in camera 1, one per match
  std::vector<char> outlier;  // per match
  std::vector<feature::OrbKeypoint> keypoints1, keypoints2;
  std::vector<match::Match> matches;  // i -> i
};

struct SceneSpec {
  bool planar = false;
  int points = 300;
  double noise_px = 0.7;
  double outlier_fraction = 0.1;
  Vec3 rotation_axis_angle = Vec3(0.02, -0.08, 0.03);  // radians
  Vec3 t21 = Vec3(-0.6, 0.1, 0.15);                    // metres
  std::uint64_t seed = 1;
};

inline Vec2 project_px(const PinholeIntrinsics& k, const Vec3& p) {
  return {k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy};
}

inline bool in_image(const Vec2& uv) {
  return uv.x() >= 0.0 && uv.x() < 640.0 && uv.y() >= 0.0 && uv.y() < 480.0;
}

inline TwoViewScene make_scene(const SceneSpec& spec) {
  TwoViewScene s;
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> ux(-3.0, 3.0), uy(-2.2, 2.2), uz(4.0, 10.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0), upx(0.0, 640.0), upy(0.0, 480.0);
  std::normal_distribution<double> noise(0.0, spec.noise_px);
  s.R21 = SO3::exp(spec.rotation_axis_angle).matrix();
  s.t21 = spec.t21;
  while (static_cast<int>(s.points1.size()) < spec.points) {
    Vec3 X(ux(rng), uy(rng), uz(rng));
    if (spec.planar) X.y() = 1.0;  // a floor 1 m below the first camera
    const Vec3 X2 = s.R21 * X + s.t21;
    if (X2.z() <= 0.1) continue;
    Vec2 a = project_px(s.k, X), b = project_px(s.k, X2);
    if (!in_image(a) || !in_image(b)) continue;
    const bool is_outlier = u01(rng) < spec.outlier_fraction;
    a += Vec2(noise(rng), noise(rng));
    b = is_outlier ? Vec2(upx(rng), upy(rng)) : Vec2(b + Vec2(noise(rng), noise(rng)));
    const int i = static_cast<int>(s.points1.size());
    s.points1.push_back(X);
    s.outlier.push_back(is_outlier);
    feature::OrbKeypoint ka, kb;
    ka.x = static_cast<float>(a.x());
    ka.y = static_cast<float>(a.y());
    kb.x = static_cast<float>(b.x());
    kb.y = static_cast<float>(b.y());
    s.keypoints1.push_back(ka);
    s.keypoints2.push_back(kb);
    s.matches.push_back({i, i, 0});
  }
  return s;
}

// Pixel homography of the plane n^T X1 = d under X2 = R X1 + t.
inline Mat3 plane_homography(const PinholeIntrinsics& k, const Mat3& R, const Vec3& t,
                             const Vec3& n, double d) {
  const Mat3 K = geometry::camera_matrix(k);
  return K * (R + t * n.transpose() / d) * K.inverse();
}

// The scene's matches as the two-view solvers read them (every keypoint at level 0: sigma 1 px).
inline geometry::Correspondences correspondences_of(const TwoViewScene& s) {
  geometry::Correspondences c;
  for (std::size_t i = 0; i < s.keypoints1.size(); ++i)
    c.add(Vec2(s.keypoints1[i].x, s.keypoints1[i].y), Vec2(s.keypoints2[i].x, s.keypoints2[i].y));
  return c;
}

inline double rotation_error_deg(const Mat3& a, const Mat3& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

inline double direction_error_deg(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace sbaslam::test
