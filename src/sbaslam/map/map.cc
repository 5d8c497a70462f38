#include "sbaslam/map/map.h"

#include <thread>

namespace sbaslam::map {

std::unique_lock<std::mutex> Map::lock_for_tracking() {
  ++tracking_waiting_;
  std::unique_lock<std::mutex> lock(mutex_);
  --tracking_waiting_;
  return lock;
}

void Map::yield_to_tracking(std::unique_lock<std::mutex>& lock) {
  if (tracking_waiting_.load() == 0) return;
  lock.unlock();
  // The waiter was woken by the unlock; it owns the lock within microseconds.
  while (tracking_waiting_.load() > 0) std::this_thread::yield();
  lock.lock();
}

KeyFrame* Map::create_keyframe(std::size_t frame_id, double timestamp, const SE3& T_cw,
                               MeasurementsPtr measurements, const CameraRig* rig,
                               std::size_t map_id) {
  keyframe_storage_.push_back(std::make_unique<KeyFrame>(next_keyframe_id_++, frame_id, timestamp,
                                                         T_cw, std::move(measurements), rig, this));
  KeyFrame* kf = keyframe_storage_.back().get();
  kf->map_id_ = map_id;
  keyframes_.insert(kf);
  ++live_keyframes_per_map_[map_id];
  if (map_id >= next_map_id_) next_map_id_ = map_id + 1;
  if (first_keyframe_ == nullptr) first_keyframe_ = kf;
  return kf;
}

MapPoint* Map::create_map_point(const Vec3& position, KeyFrame* reference) {
  map_point_storage_.push_back(
      std::make_unique<MapPoint>(next_map_point_id_++, position, reference, this));
  MapPoint* mp = map_point_storage_.back().get();
  map_points_.insert(mp);
  return mp;
}

std::vector<MapPoint*> Map::map_points() const {
  return {map_points_.begin(), map_points_.end()};
}

void Map::erase_keyframe(KeyFrame* kf) {
  if (keyframes_.erase(kf) > 0) --live_keyframes_per_map_[kf->map_id()];
}

std::size_t Map::keyframe_count_in_map(std::size_t map_id) const {
  const auto it = live_keyframes_per_map_.find(map_id);
  return it == live_keyframes_per_map_.end() ? 0 : it->second;
}

void Map::move_keyframes_to_map(std::size_t from, std::size_t to) {
  if (from == to) return;
  for (const std::unique_ptr<KeyFrame>& kf : keyframe_storage_)
    if (kf->map_id_ == from) kf->map_id_ = to;
  live_keyframes_per_map_[to] += keyframe_count_in_map(from);
  live_keyframes_per_map_.erase(from);
}

void Map::discard_keyframe(KeyFrame* kf) {
  for (KeyFrame* other : kf->covisibles()) other->erase_connection(kf);
  erase_keyframe(kf);
  if (first_keyframe_ == kf) first_keyframe_ = keyframes_.empty() ? nullptr : *keyframes_.begin();
}

void Map::reset() {
  keyframes_.clear();
  map_points_.clear();
  keyframe_storage_.clear();
  map_point_storage_.clear();
  live_keyframes_per_map_.clear();
  first_keyframe_ = nullptr;
}

}  // namespace sbaslam::map
