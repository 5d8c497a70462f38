#pragma once
// A 3-D landmark: position, representative descriptor, viewing direction and the distance range
// over which ORB can detect it (scale invariance), plus the keyframes observing it.
//
// Thread-safety: MapPoint has no lock of its own. Every read or write happens under the map lock
// (Map::mutex()), held by tracking for its whole per-frame step and by local mapping while it
// changes the map; see docs/ARCHITECTURE.md.

#include <cstddef>
#include <map>
#include <opencv2/core.hpp>

#include "sbaslam/core/lie.h"
#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::map {

class KeyFrame;
class Map;

// Orders keyframes by id so that iterating a point's observations is deterministic.
struct KeyFrameIdLess {
  bool operator()(const KeyFrame* a, const KeyFrame* b) const;
};

class MapPoint {
  // First, in the object's first cache lines: what tracking reads of every local point each frame
  // (tens of thousands of points; scattered fields cost a cache miss each).
 public:
  // Per-frame scratch of tracking (ORB-SLAM's mnTrackReferenceForFrame and friends).
  std::size_t track_reference_for_frame = static_cast<std::size_t>(-1);
  std::size_t last_seen_frame = static_cast<std::size_t>(-1);

 private:
  bool bad_ = false;
  int visible_ = 1;
  int found_ = 1;
  Vec3 position_;
  Vec3 normal_ = Vec3::Zero();
  double min_distance_ = 0.0;
  double max_distance_ = 0.0;

 public:
  using Observations = std::map<KeyFrame*, std::size_t, KeyFrameIdLess>;

  MapPoint(std::size_t id, const Vec3& position, KeyFrame* reference, Map* map);

  std::size_t id() const { return id_; }
  const Vec3& position() const { return position_; }
  void set_position(const Vec3& p) { position_ = p; }

  // Observations: keyframe -> keypoint index. A stereo observation counts twice, as in ORB-SLAM.
  const Observations& observations() const { return observations_; }
  int observation_count() const { return observation_count_; }
  void add_observation(KeyFrame* kf, std::size_t keypoint);
  // Removes kf's observation; the point turns bad when two or fewer measurements remain.
  void erase_observation(KeyFrame* kf);
  bool is_in_keyframe(const KeyFrame* kf) const {
    return observations_.count(const_cast<KeyFrame*>(kf)) > 0;
  }
  long keypoint_in(const KeyFrame* kf) const;

  // Detaches the point from all keyframes and the map. It stays allocated (the map owns it) so
  // that stale pointers in frames can still test is_bad().
  void set_bad();
  bool is_bad() const { return bad_; }
  // Hands all observations to `other` (duplicate fusion) and turns bad.
  void replace_with(MapPoint* other);
  MapPoint* replaced_by() const { return replaced_by_; }

  // The observed descriptor with the least median distance to the others.
  void update_descriptor();
  const cv::Mat& descriptor() const { return descriptor_; }
  // Mean viewing direction and the scale-invariance distance range, from the reference keyframe.
  void update_normal_and_depth();
  const Vec3& normal() const { return normal_; }
  double min_distance() const { return 0.8 * min_distance_; }
  double max_distance() const { return 1.2 * max_distance_; }
  // Pyramid level at which the point should appear from `distance`.
  int predict_level(double distance, const feature::ScaleLevels& levels) const;

  KeyFrame* reference_keyframe() const { return reference_; }
  std::size_t first_keyframe_id() const { return first_keyframe_id_; }

  // Tracking statistics: how often the point was predicted visible, and actually matched.
  void increase_visible(int n = 1) { visible_ += n; }
  void increase_found(int n = 1) { found_ += n; }
  double found_ratio() const { return static_cast<double>(found_) / visible_; }
  int visible() const { return visible_; }
  int found() const { return found_; }

  // Filled by tracking's visibility check for the projection search.
  bool track_in_view = false;
  int track_scale_level = 0;
  double track_proj_x = 0.0, track_proj_y = 0.0, track_proj_xr = -1.0;
  double track_view_cos = 0.0;
  std::size_t fuse_candidate_for_keyframe = static_cast<std::size_t>(-1);
  std::size_t ba_local_for_keyframe = static_cast<std::size_t>(-1);

 private:
  friend class MapFile;  // map_file.h

  std::size_t id_;
  std::size_t first_keyframe_id_;
  cv::Mat descriptor_;
  Observations observations_;
  int observation_count_ = 0;
  KeyFrame* reference_;
  Map* map_;
  MapPoint* replaced_by_ = nullptr;
};

}  // namespace sbaslam::map
