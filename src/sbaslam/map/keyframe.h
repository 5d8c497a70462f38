#pragma once
// A keyframe: a frame kept in the map, with its pose, its measurements, the map points it
// observes, its place in the covisibility graph (weighted by shared points) and in the spanning
// tree that loop closing uses.
//
// Thread-safety: no lock of its own; all access under the map lock (Map::mutex()).

#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/map/map_point.h"
#include "sbaslam/map/measurements.h"

namespace sbaslam::map {

class KeyFrame {
 public:
  // The rig outlives the map (the system owns both).
  KeyFrame(std::size_t id, std::size_t frame_id, double timestamp, const SE3& T_cw,
           MeasurementsPtr measurements, const CameraRig* rig, Map* map);

  std::size_t id() const { return id_; }
  std::size_t frame_id() const { return frame_id_; }
  // The map (one initialisation's connected keyframes) this keyframe belongs to; a merge moves a
  // whole map's keyframes into the other map (Map::move_keyframes_to_map).
  std::size_t map_id() const { return map_id_; }
  double timestamp() const { return timestamp_; }

  const SE3& T_cw() const { return T_cw_; }
  const SE3& T_wc() const { return T_wc_; }
  void set_pose(const SE3& T_cw);
  const Vec3& camera_center() const { return T_wc_.translation(); }

  const CameraRig& rig() const { return *rig_; }
  const Measurements& measurements() const { return *measurements_; }
  const MeasurementsPtr& measurements_ptr() const { return measurements_; }
  std::size_t keypoint_count() const { return measurements_->size(); }

  // Map point associations, one slot per keypoint (nullptr when none).
  MapPoint* map_point(std::size_t i) const { return map_points_[i]; }
  const std::vector<MapPoint*>& map_points() const { return map_points_; }
  void add_map_point(MapPoint* mp, std::size_t i) { map_points_[i] = mp; }
  void erase_map_point(std::size_t i) { map_points_[i] = nullptr; }
  void erase_map_point(const MapPoint* mp);
  // Good points observed by at least `min_observations` keyframes.
  int tracked_map_points(int min_observations) const;

  // Recomputes the covisibility edges from the shared map points (weight >= 15, or the best one),
  // and attaches the keyframe to the spanning tree on its first call.
  void update_connections();
  void add_connection(KeyFrame* kf, int weight);
  void erase_connection(KeyFrame* kf);
  int connection_weight(KeyFrame* kf) const;
  std::vector<KeyFrame*> covisibles() const { return ordered_connections_; }
  std::vector<KeyFrame*> best_covisibles(std::size_t n) const;
  std::vector<KeyFrame*> covisibles_with_weight_at_least(int weight) const;

  KeyFrame* parent() const { return parent_; }
  const std::set<KeyFrame*, KeyFrameIdLess>& children() const { return children_; }
  void add_child(KeyFrame* kf) { children_.insert(kf); }
  void erase_child(KeyFrame* kf) { children_.erase(kf); }
  void change_parent(KeyFrame* kf);
  void add_loop_edge(KeyFrame* kf) {
    loop_edges_.insert(kf);
    not_erase_ = true;
  }
  const std::set<KeyFrame*, KeyFrameIdLess>& loop_edges() const { return loop_edges_; }

  // Removes the keyframe from the graph and its points' observations, re-parenting its children
  // in the spanning tree. The first keyframe and keyframes protected by loop closing stay.
  void set_bad();
  bool is_bad() const { return bad_; }
  // Pose relative to the parent at the time the keyframe turned bad, so that frames referring to
  // it can still be placed through the spanning tree.
  const SE3& T_cp() const { return T_cp_; }
  void set_not_erase(bool not_erase) { not_erase_ = not_erase; }
  // The first keyframe of a map (or of a new map started after a loss) anchors the gauge: BA
  // keeps it fixed and culling never removes it. A map merged into another stops anchoring; its
  // origin keeps the place in the joined spanning tree that the merge gave it.
  bool is_origin() const { return origin_; }
  void set_origin(bool origin = true) {
    origin_ = origin;
    if (!origin) first_connection_ = false;
  }

  // World point of a keypoint with a stereo/RGB-D depth.
  std::optional<Vec3> unproject_stereo(std::size_t i) const;
  // The q-quantile (0.5: median) of the depths of the observed map points.
  double scene_depth_quantile(double q) const;
  // Keypoints whose undistorted position is within r of (x, y), levels in [min_level, max_level]
  // (max_level < 0: any).
  std::vector<std::size_t> features_in_area(double x, double y, double r, int min_level = 0,
                                            int max_level = -1) const;

  // Per-keyframe scratch of the mapping and tracking steps (ORB-SLAM's mnBALocalForKF etc.).
  std::size_t ba_local_for_keyframe = static_cast<std::size_t>(-1);
  std::size_t ba_fixed_for_keyframe = static_cast<std::size_t>(-1);
  std::size_t track_reference_for_frame = static_cast<std::size_t>(-1);
  std::size_t fuse_target_for_keyframe = static_cast<std::size_t>(-1);
  // Tracking's count of the current frame's points this keyframe observes, valid while
  // `track_votes_round` is the tracker's current voting round.
  std::size_t track_votes_round = 0;
  int track_votes = 0;

 private:
  void sort_connections();

  friend class Map;
  friend class MapFile;  // map_file.h: saves and restores the private state

  std::size_t id_;
  std::size_t map_id_ = 0;
  std::size_t frame_id_;
  double timestamp_;
  SE3 T_cw_;
  SE3 T_wc_;
  MeasurementsPtr measurements_;
  const CameraRig* rig_;
  std::vector<MapPoint*> map_points_;
  Map* map_;

  std::map<KeyFrame*, int, KeyFrameIdLess> connection_weights_;
  std::vector<KeyFrame*> ordered_connections_;
  std::vector<int> ordered_weights_;
  bool first_connection_ = true;
  KeyFrame* parent_ = nullptr;
  std::set<KeyFrame*, KeyFrameIdLess> children_;
  std::set<KeyFrame*, KeyFrameIdLess> loop_edges_;
  bool not_erase_ = false;
  bool origin_ = false;
  bool bad_ = false;
  SE3 T_cp_;
};

}  // namespace sbaslam::map
