#include "sbaslam/map/keyframe.h"

#include <algorithm>

#include "sbaslam/map/map.h"

namespace sbaslam::map {
namespace {
// Keyframes sharing at least this many points are linked in the covisibility graph.
constexpr int kCovisibilityThreshold = 15;
}  // namespace

KeyFrame::KeyFrame(std::size_t id, std::size_t frame_id, double timestamp, const SE3& T_cw,
                   MeasurementsPtr measurements, const CameraRig* rig, Map* map)
    : id_(id),
      frame_id_(frame_id),
      timestamp_(timestamp),
      measurements_(std::move(measurements)),
      rig_(rig),
      map_points_(measurements_->size(), nullptr),
      map_(map) {
  set_pose(T_cw);
}

void KeyFrame::set_pose(const SE3& T_cw) {
  T_cw_ = T_cw;
  T_wc_ = T_cw.inverse();
}

void KeyFrame::erase_map_point(const MapPoint* mp) {
  const long i = mp->keypoint_in(this);
  if (i >= 0) map_points_[static_cast<std::size_t>(i)] = nullptr;
}

int KeyFrame::tracked_map_points(int min_observations) const {
  int count = 0;
  for (const MapPoint* mp : map_points_)
    if (mp && !mp->is_bad() && mp->observation_count() >= min_observations) ++count;
  return count;
}

void KeyFrame::update_connections() {
  std::map<KeyFrame*, int, KeyFrameIdLess> counts;
  for (MapPoint* mp : map_points_) {
    if (!mp || mp->is_bad()) continue;
    for (const auto& [kf, index] : mp->observations())
      if (kf != this) ++counts[kf];
  }
  if (counts.empty()) return;

  KeyFrame* best = nullptr;
  int best_count = 0;
  for (const auto& [kf, count] : counts) {
    if (count > best_count) {
      best_count = count;
      best = kf;
    }
    if (count >= kCovisibilityThreshold) kf->add_connection(this, count);
  }
  connection_weights_.clear();
  for (const auto& [kf, count] : counts)
    if (count >= kCovisibilityThreshold) connection_weights_[kf] = count;
  if (connection_weights_.empty()) {
    connection_weights_[best] = best_count;
    best->add_connection(this, best_count);
  }
  sort_connections();

  if (first_connection_ && !origin_) {
    parent_ = ordered_connections_.front();
    parent_->add_child(this);
    first_connection_ = false;
  }
}

void KeyFrame::add_connection(KeyFrame* kf, int weight) {
  const auto it = connection_weights_.find(kf);
  if (it != connection_weights_.end() && it->second == weight) return;
  connection_weights_[kf] = weight;
  sort_connections();
}

void KeyFrame::erase_connection(KeyFrame* kf) {
  if (connection_weights_.erase(kf) > 0) sort_connections();
}

int KeyFrame::connection_weight(KeyFrame* kf) const {
  const auto it = connection_weights_.find(kf);
  return it == connection_weights_.end() ? 0 : it->second;
}

void KeyFrame::sort_connections() {
  std::vector<std::pair<int, KeyFrame*>> by_weight;
  by_weight.reserve(connection_weights_.size());
  for (const auto& [kf, weight] : connection_weights_) by_weight.emplace_back(weight, kf);
  // Heaviest first; ties by id so that the order never depends on pointer values.
  std::sort(by_weight.begin(), by_weight.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second->id() < b.second->id();
  });
  ordered_connections_.clear();
  ordered_weights_.clear();
  for (const auto& [weight, kf] : by_weight) {
    ordered_connections_.push_back(kf);
    ordered_weights_.push_back(weight);
  }
}

std::vector<KeyFrame*> KeyFrame::best_covisibles(std::size_t n) const {
  const std::size_t count = std::min(n, ordered_connections_.size());
  return {ordered_connections_.begin(), ordered_connections_.begin() + static_cast<long>(count)};
}

std::vector<KeyFrame*> KeyFrame::covisibles_with_weight_at_least(int weight) const {
  std::vector<KeyFrame*> out;
  for (std::size_t i = 0; i < ordered_connections_.size() && ordered_weights_[i] >= weight; ++i)
    out.push_back(ordered_connections_[i]);
  return out;
}

void KeyFrame::change_parent(KeyFrame* kf) {
  parent_ = kf;
  kf->add_child(this);
}

void KeyFrame::set_bad() {
  if (bad_ || not_erase_ || origin_) return;
  for (const auto& [kf, weight] : connection_weights_) kf->erase_connection(this);
  for (std::size_t i = 0; i < map_points_.size(); ++i)
    if (map_points_[i]) map_points_[i]->erase_observation(this);
  connection_weights_.clear();
  ordered_connections_.clear();
  ordered_weights_.clear();

  // Re-parent the children: repeatedly attach the child with the strongest covisibility to a
  // keyframe already in the tree (the parent or an already re-parented child).
  std::set<KeyFrame*, KeyFrameIdLess> candidates{parent_};
  while (!children_.empty()) {
    KeyFrame* best_child = nullptr;
    KeyFrame* best_parent = nullptr;
    int best_weight = -1;
    for (KeyFrame* child : children_) {
      if (child->is_bad()) continue;
      for (KeyFrame* candidate : child->covisibles()) {
        if (!candidates.count(candidate)) continue;
        const int w = child->connection_weight(candidate);
        if (w > best_weight) {
          best_weight = w;
          best_child = child;
          best_parent = candidate;
        }
      }
    }
    if (best_child == nullptr) break;
    best_child->change_parent(best_parent);
    candidates.insert(best_child);
    children_.erase(best_child);
  }
  for (KeyFrame* child : children_) child->change_parent(parent_);
  children_.clear();
  if (parent_) {
    parent_->erase_child(this);
    T_cp_ = T_cw_ * parent_->T_wc();
  }
  bad_ = true;
  map_->erase_keyframe(this);
}

std::optional<Vec3> KeyFrame::unproject_stereo(std::size_t i) const {
  const float z = measurements_->depth[i];
  if (z <= 0.0f) return std::nullopt;
  const feature::OrbKeypoint& kp = measurements_->keypoints_un[i];
  const PinholeIntrinsics& k = rig_->camera.intrinsics();
  const Vec3 p_c((kp.x - k.cx) * z / k.fx, (kp.y - k.cy) * z / k.fy, z);
  return T_wc_ * p_c;
}

double KeyFrame::scene_depth_quantile(double q) const {
  std::vector<double> depths;
  const Vec3 row_z = T_cw_.rotation().row(2).transpose();
  const double t_z = T_cw_.translation().z();
  for (const MapPoint* mp : map_points_)
    if (mp && !mp->is_bad()) depths.push_back(row_z.dot(mp->position()) + t_z);
  if (depths.empty()) return -1.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(depths.size() - 1));
  std::nth_element(depths.begin(), depths.begin() + static_cast<long>(k), depths.end());
  return depths[k];
}

std::vector<std::size_t> KeyFrame::features_in_area(double x, double y, double r, int min_level,
                                                    int max_level) const {
  const std::vector<int> found = measurements_->grid.features_in_area(
      static_cast<float>(x), static_cast<float>(y), static_cast<float>(r), min_level, max_level);
  return {found.begin(), found.end()};
}

}  // namespace sbaslam::map
