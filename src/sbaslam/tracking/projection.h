#pragma once
// Projection of map points into a frame: the frustum test of the local-map search, and the
// searches by projection from the last frame and from the local map (ORB-SLAM's
// SearchByProjection variants), built on match::match_by_projection.

#include <vector>

#include "sbaslam/map/map_point.h"
#include "sbaslam/map/measurements.h"
#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/tracking/frame.h"

namespace sbaslam::tracking {

// ORB-SLAM's isInFrustum: the point projects inside the image, lies within its scale-invariance
// distance range and is seen within acos(min_view_cos) of its mean viewing direction. Fills the
// point's track_* fields.
bool is_in_frustum(map::MapPoint& mp, const Frame& frame, const map::CameraRig& rig,
                   double min_view_cos);

// Matches the last frame's map points into `current` around their projection with the current
// pose estimate. Returns the number of new matches written into current.map_points.
int search_from_last_frame(Frame& current, const Frame& last, const map::CameraRig& rig,
                           float radius);

// Matches local map points (already tested with is_in_frustum) that the frame does not yet see.
int search_local_points(Frame& frame, const std::vector<map::MapPoint*>& points,
                        const map::CameraRig& rig, float radius);

// Matches the keyframe's map points into the frame around their projection with the frame's pose.
// `already` holds points the frame already matched (skipped).
int search_from_keyframe(Frame& frame, const map::KeyFrame& kf, const map::CameraRig& rig,
                         float radius, int max_distance);

match::FrameView frame_view(const Frame& frame, const map::CameraRig& rig);

// A frame keypoint matched to a keyframe's map point.
struct PointMatch {
  std::size_t keypoint = 0;  // in the frame
  map::MapPoint* point = nullptr;
};

// The keyframe's map points matched to the frame by descriptor alone (TH_LOW, ratio test), the
// stand-in for ORB-SLAM's bag-of-words search: reference-keyframe tracking and relocalisation.
std::vector<PointMatch> match_keyframe_points_by_descriptor(const map::KeyFrame& kf,
                                                            const Frame& frame, float nn_ratio);

}  // namespace sbaslam::tracking
