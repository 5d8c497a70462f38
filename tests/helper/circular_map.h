#pragma once
// A map as monocular SLAM would leave it after driving once around a circle: keyframes whose
// poses drift (a growing rotation and offset of the world), points placed where the drifted
// keyframe that first saw them put them, and duplicates of the first keyframes' points where the
// drive comes back without recognising them. Each world point has its own random descriptor, so
// descriptor matching is exact. For loop detection and correction tests.

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "helper/camera_rig.h"
#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/map/map.h"

namespace sbaslam::test {

struct CircularMap {
  map::CameraRig rig = vga_mono_rig();
  map::Map map;
  std::vector<map::KeyFrame*> keyframes;
  std::vector<SE3> true_T_cw;  // per keyframe
  std::vector<SE3> drift;      // per keyframe: estimated world = drift * true world
  std::vector<Vec3> world_points;
  std::vector<map::MapPoint*> first_point;       // per world point: its first map point, or nullptr
  std::vector<std::vector<int>> world_point_of;  // per keyframe and keypoint
  cv::Mat descriptors;                           // per world point

  // Where keyframe i should be once the map is made consistent with keyframe `anchor`'s world.
  SE3 ideal_T_cw(std::size_t i, std::size_t anchor) const {
    return true_T_cw[i] * drift[anchor].inverse();
  }
};

struct CircularMapOptions {
  int keyframes = 40;  // 36 make a full turn; the rest go around again
  double step_deg = 10.0;
  double radius = 20.0;       // of the drive
  double wall_radius = 32.0;  // points on a cylinder around it
  int points = 3000;
  // Small enough that a point's views (about five keyframes) agree within ~2 px.
  double drift_deg_per_keyframe = 0.05;
  double drift_m_per_keyframe = 0.02;
  int track_gap = 2;  // a point unseen for more keyframes than this is made anew
  unsigned seed = 7;
  // From this keyframe on (if >= 0), a second map, as tracking makes one after a loss: its own
  // origin and points, and a world off the first map's by map_jump (the way driven while lost:
  // keyframes are 3.5 m and 0.1 s apart).
  int new_map_from = -1;
  SE3 map_jump = SE3(SO3::exp(Vec3(0.0, 0.05, 0.0)), Vec3(2.0, 0.0, -3.0));
};

inline SE3 circle_pose(double angle_deg, double radius) {
  // Camera on the circle in the x-z plane (y down), looking along the direction of travel.
  const double a = angle_deg * M_PI / 180.0;
  const Vec3 center(radius * std::cos(a), 0.0, radius * std::sin(a));
  const Mat3 R_wc = (SO3::exp(Vec3(0.0, -a, 0.0))).matrix();  // forward (+z) along the tangent
  return SE3(SO3::from_matrix(R_wc), center).inverse();
}

inline map::MeasurementsPtr measure(const map::CameraRig& rig, const SE3& T_cw,
                                    const std::vector<Vec3>& points, const cv::Mat& descriptors,
                                    std::vector<int>& seen) {
  auto m = std::make_shared<map::Measurements>();
  seen.clear();
  for (std::size_t j = 0; j < points.size(); ++j) {
    const Vec3 p = T_cw * points[j];
    if (p.z() < 1.0 || p.norm() > 40.0) continue;
    const Vec2 uv = rig.camera.project(p);
    if (!rig.in_image(uv)) continue;
    feature::OrbKeypoint kp;
    kp.x = static_cast<float>(uv.x());
    kp.y = static_cast<float>(uv.y());
    // The octave grows with distance as ORB's pyramid would find it, so that the scale a point
    // is predicted at from any view agrees with the keypoint there.
    kp.octave =
        std::clamp(static_cast<int>(std::lround(std::log(p.norm() / 8.0) / std::log(1.2))), 0, 7);
    m->keypoints.push_back(kp);
    seen.push_back(static_cast<int>(j));
  }
  m->keypoints_un = m->keypoints;
  m->descriptors = cv::Mat(static_cast<int>(seen.size()), 32, CV_8U);
  for (std::size_t i = 0; i < seen.size(); ++i)
    descriptors.row(seen[i]).copyTo(m->descriptors.row(static_cast<int>(i)));
  m->u_right.assign(seen.size(), -1.0f);
  m->depth.assign(seen.size(), -1.0f);
  m->weights.assign(seen.size(), 1.0f);
  m->grid = match::FeatureGrid(m->keypoints_un, rig.bounds);
  return m;
}

inline std::unique_ptr<CircularMap> make_circular_map(const CircularMapOptions& o = {}) {
  auto c = std::make_unique<CircularMap>();
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), height(-4.0, 4.0);
  std::uniform_int_distribution<int> byte(0, 255);
  cv::Mat& descriptors = c->descriptors;
  descriptors.create(o.points, 32, CV_8U);
  for (int j = 0; j < o.points; ++j) {
    const double a = angle(rng);
    c->world_points.emplace_back(o.wall_radius * std::cos(a), height(rng),
                                 o.wall_radius * std::sin(a));
    for (int b = 0; b < 32; ++b)
      descriptors.at<std::uint8_t>(j, b) = static_cast<std::uint8_t>(byte(rng));
  }
  std::vector<map::MapPoint*> current(o.points, nullptr);
  std::vector<int> last_seen(o.points, -1000);
  c->first_point.assign(o.points, nullptr);
  std::vector<int> seen;
  // Odometry's error: each step's relative pose is off by the same small turn and offset in the
  // camera's own frame, so the estimated path curls away from the true one.
  const SE3 step_error(SO3::exp(Vec3(0.0, o.drift_deg_per_keyframe * M_PI / 180.0, 0.0)),
                       Vec3(o.drift_m_per_keyframe, 0.0, 0.0));
  SE3 T_est_wc;
  std::size_t map_id = c->map.new_map_id();
  for (int i = 0; i < o.keyframes; ++i) {
    const SE3 T_true = circle_pose(i * o.step_deg, o.radius);
    if (i > 0)
      T_est_wc = T_est_wc * (c->true_T_cw.back() * T_true.inverse()) * step_error;
    else
      T_est_wc = T_true.inverse();
    const bool new_map = i == o.new_map_from;
    if (new_map) {
      map_id = c->map.new_map_id();
      T_est_wc = o.map_jump * T_est_wc;
      std::fill(current.begin(), current.end(), nullptr);
    }
    const SE3 W = T_est_wc * T_true;  // true world -> estimated world, as keyframe i sees it
    map::MeasurementsPtr m = measure(c->rig, T_true, c->world_points, descriptors, seen);
    map::KeyFrame* kf = c->map.create_keyframe(static_cast<std::size_t>(i), 0.1 * i,
                                               T_true * W.inverse(), m, &c->rig, map_id);
    if (i == 0 || new_map) kf->set_origin();
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const int j = seen[k];
      if (!current[j] || i - last_seen[j] > o.track_gap) {
        current[j] = c->map.create_map_point(W * c->world_points[j], kf);
        if (!c->first_point[j]) c->first_point[j] = current[j];
      }
      last_seen[j] = i;
      kf->add_map_point(current[j], k);
      current[j]->add_observation(kf, k);
    }
    for (map::MapPoint* mp : c->map.map_points()) {
      mp->update_descriptor();
      mp->update_normal_and_depth();
    }
    kf->update_connections();
    c->keyframes.push_back(kf);
    c->true_T_cw.push_back(T_true);
    c->drift.push_back(W);
    c->world_point_of.push_back(seen);
  }
  return c;
}

// A vocabulary trained on the map's own keyframes (every world point its own word, nearly).
inline loop::Vocabulary vocabulary_of(const CircularMap& c) {
  std::vector<cv::Mat> sets;
  for (const map::KeyFrame* kf : c.keyframes) sets.push_back(kf->measurements().descriptors);
  return loop::Vocabulary::train(sets, loop::VocabularyTrainOptions{});
}

}  // namespace sbaslam::test
