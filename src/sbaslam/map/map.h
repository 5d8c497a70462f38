#pragma once
// The map: it owns every keyframe and map point. Objects are never freed while the map lives
// (bad ones are only unlinked), so pointers held by frames stay valid; reset() frees everything.
//
// One lock guards the whole map (mutex()). Tracking holds it for its per-frame step after feature
// extraction; local mapping holds it while it edits the map, releases it while Ceres solves a
// BA problem built from a copy, and steps aside between its edits when tracking waits
// (yield_to_tracking). There are no per-object locks; see docs/ARCHITECTURE.md.

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "sbaslam/map/keyframe.h"
#include "sbaslam/map/map_point.h"

namespace sbaslam::map {

class Map {
 public:
  std::mutex& mutex() { return mutex_; }
  // Takes the lock for tracking's per-frame step, announcing the wait to yield_to_tracking().
  std::unique_lock<std::mutex> lock_for_tracking();
  // Local mapping calls this, holding the lock, between edits that leave the map consistent: if
  // tracking waits, the lock goes to tracking first (std::mutex alone would let the releasing
  // thread take it straight back). Returns with the lock held.
  void yield_to_tracking(std::unique_lock<std::mutex>& lock);

  // Each initialisation (the first and every one after a loss) starts a map of its own.
  std::size_t new_map_id() { return next_map_id_++; }
  KeyFrame* create_keyframe(std::size_t frame_id, double timestamp, const SE3& T_cw,
                            MeasurementsPtr measurements, const CameraRig* rig,
                            std::size_t map_id = 0);
  MapPoint* create_map_point(const Vec3& position, KeyFrame* reference);

  // Unlinks (called by set_bad); the objects stay allocated.
  void erase_keyframe(KeyFrame* kf);
  void erase_map_point(MapPoint* mp) { map_points_.erase(mp); }
  // Removes a keyframe that never entered the graph (a rejected initialisation), origin or not.
  void discard_keyframe(KeyFrame* kf);

  // Live objects, ordered by id (deterministic iteration).
  std::vector<KeyFrame*> keyframes() const { return {keyframes_.begin(), keyframes_.end()}; }
  std::vector<MapPoint*> map_points() const;
  std::size_t keyframe_count() const { return keyframes_.size(); }
  // Live keyframes of one map: ORB-SLAM3's KeyFramesInMap, which decides how young a map is.
  std::size_t keyframe_count_in_map(std::size_t map_id) const;
  const std::map<std::size_t, std::size_t>& live_keyframes_per_map() const {
    return live_keyframes_per_map_;
  }
  // A merge: every keyframe of map `from`, live or bad, now belongs to map `to`.
  void move_keyframes_to_map(std::size_t from, std::size_t to);
  std::size_t map_point_count() const { return map_points_.size(); }
  std::size_t max_keyframe_id() const { return next_keyframe_id_ == 0 ? 0 : next_keyframe_id_ - 1; }
  KeyFrame* first_keyframe() const { return first_keyframe_; }

  // Counts the corrections that move the whole map at once (a loop closure, a global BA; ORB-SLAM's
  // big-change index). A local BA solved across one must not be applied, and tracking re-places its
  // last frame from its reference keyframe.
  std::size_t big_change_index() const { return big_change_index_; }
  void notify_big_change() { ++big_change_index_; }

  // Frees every keyframe and map point; ids keep counting up so that they stay unique.
  void reset();

 private:
  friend class MapFile;  // map_file.h

  struct MapPointIdLess {
    bool operator()(const MapPoint* a, const MapPoint* b) const { return a->id() < b->id(); }
  };

  std::mutex mutex_;
  std::atomic<int> tracking_waiting_{0};
  std::atomic<std::size_t> big_change_index_{0};
  std::vector<std::unique_ptr<KeyFrame>> keyframe_storage_;
  std::vector<std::unique_ptr<MapPoint>> map_point_storage_;
  std::set<KeyFrame*, KeyFrameIdLess> keyframes_;
  std::set<MapPoint*, MapPointIdLess> map_points_;
  std::map<std::size_t, std::size_t> live_keyframes_per_map_;
  KeyFrame* first_keyframe_ = nullptr;
  std::size_t next_map_id_ = 0;
  std::size_t next_keyframe_id_ = 0;
  std::size_t next_map_point_id_ = 0;
};

}  // namespace sbaslam::map
