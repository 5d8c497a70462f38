#pragma once
// A frame being tracked: the front end's measurements (shared with the keyframe it may become)
// plus tracking's own state — the map point matched to each keypoint, outlier flags and the pose.
// Frames belong to the tracking thread; the map points they point to are read under the map lock.

#include <cstddef>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/map/keyframe.h"
#include "sbaslam/map/measurements.h"

namespace sbaslam::tracking {

struct Frame {
  std::size_t id = 0;
  double timestamp = 0.0;
  map::MeasurementsPtr measurements;
  std::vector<map::MapPoint*> map_points;  // one slot per keypoint
  std::vector<char> outlier;               // one flag per keypoint
  SE3 T_cw;
  bool has_pose = false;
  map::KeyFrame* reference_keyframe = nullptr;

  Frame() = default;
  Frame(std::size_t frame_id, double stamp, map::MeasurementsPtr m)
      : id(frame_id),
        timestamp(stamp),
        measurements(std::move(m)),
        map_points(measurements->size(), nullptr),
        outlier(measurements->size(), 0) {}

  std::size_t size() const { return map_points.size(); }
  const map::Measurements& m() const { return *measurements; }
  Vec3 camera_center() const { return T_cw.inverse().translation(); }
  void set_pose(const SE3& pose) {
    T_cw = pose;
    has_pose = true;
  }
  // Good map points matched in this frame (outliers included).
  int matched_count() const;
  // Drops outlier matches; returns how many good matches remain.
  int discard_outliers();
};

}  // namespace sbaslam::tracking
