#pragma once
// Two keyframes with a known similarity between their camera frames and matched map points, for
// the loop's Sim3 RANSAC and refinement tests. Keyframe 2's map carries a scale drift s, as a
// monocular map does at a loop: p1 = S12 p2 = s R p2 + t.

#include <cmath>
#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/optimize/sim3_refinement.h"
#include "sbaslam/sim/random.h"

namespace sbaslam::test {

struct Sim3SceneSpec {
  int count = 100;
  double wrong_fraction = 0.0;  // pairs whose KF2 point is another point of KF2
  double pixel_noise = 0.0;     // keypoint noise at level 0 (px), grows with the level's scale
  double depth_noise = 0.0;     // map point noise per axis, as a fraction of the depth
  double scale = 1.4;           // s of S12; 1 for a stereo (SE3) loop
  std::uint64_t seed = 1;
};

struct Sim3Scene {
  PinholeCamera camera1{PinholeIntrinsics{500.0, 500.0, 320.0, 240.0}};
  PinholeCamera camera2{PinholeIntrinsics{520.0, 515.0, 330.0, 235.0}};
  Sim3 S12;
  std::vector<optimize::Sim3Correspondence> pairs;
  std::vector<char> is_wrong;
};

inline bool in_image(const PinholeCamera& camera, const Vec3& p_c) {
  if (p_c.z() < 0.5) return false;
  const Vec2 uv = camera.project(p_c);
  return uv.x() >= 0.0 && uv.x() < 640.0 && uv.y() >= 0.0 && uv.y() < 480.0;
}

// A world point seen by both keyframes, in each camera frame (the first in KF1's, the second in
// KF2's).
inline std::pair<Vec3, Vec3> covisible_point(const Sim3Scene& scene, sim::Random& random) {
  const Sim3 S21 = scene.S12.inverse();
  for (;;) {
    const Vec3 p1(random.uniform(-5.0, 5.0), random.uniform(-4.0, 4.0), random.uniform(4.0, 14.0));
    const Vec3 p2 = S21 * p1;
    if (in_image(scene.camera1, p1) && in_image(scene.camera2, p2)) return {p1, p2};
  }
}

inline Vec3 noisy(const Vec3& p, double fraction, sim::Random& random) {
  const double sigma = fraction * p.z();
  return p + sigma * Vec3(random.normal(), random.normal(), random.normal());
}

inline Vec2 keypoint(const PinholeCamera& camera, const Vec3& p_c, double sigma,
                     sim::Random& random) {
  return camera.project(p_c) + sigma * Vec2(random.normal(), random.normal());
}

inline Sim3Scene make_sim3_scene(const Sim3SceneSpec& spec) {
  Sim3Scene scene;
  scene.S12 = Sim3(spec.scale, SO3::exp(Vec3(0.04, -0.25, 0.03)), Vec3(1.2, -0.1, 0.6));
  sim::Random random(spec.seed);
  for (int i = 0; i < spec.count; ++i) {
    const auto [p1, p2_true] = covisible_point(scene, random);
    const bool wrong = random.chance(spec.wrong_fraction);
    const Vec3 p2 = wrong ? covisible_point(scene, random).second : p2_true;
    const int level1 = random.integer(0, 3), level2 = random.integer(0, 3);
    optimize::Sim3Correspondence pair;
    pair.sigma2_1 = std::pow(1.44, level1);  // ORB-SLAM's sigma2 for scale factor 1.2
    pair.sigma2_2 = std::pow(1.44, level2);
    pair.p1_c = noisy(p1, spec.depth_noise, random);
    pair.p2_c = noisy(p2, spec.depth_noise, random);
    pair.uv1 = keypoint(scene.camera1, p1, spec.pixel_noise * std::sqrt(pair.sigma2_1), random);
    pair.uv2 = keypoint(scene.camera2, p2, spec.pixel_noise * std::sqrt(pair.sigma2_2), random);
    scene.pairs.push_back(pair);
    scene.is_wrong.push_back(wrong);
  }
  return scene;
}

inline double rotation_error_deg(const Sim3& a, const Sim3& b) {
  return (a.so3().inverse() * b.so3()).angle() * 180.0 / M_PI;
}

}  // namespace sbaslam::test
