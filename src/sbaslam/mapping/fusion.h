#pragma once
// Fusion of duplicate map points between a keyframe and its neighbours (ORB-SLAM's
// SearchInNeighbors and Fuse): each point is projected into the other keyframe; if it matches a
// keypoint that already has a point, the one with fewer observations is replaced by the other,
// otherwise the point gains the observation.

#include <functional>
#include <vector>

#include "sbaslam/map/map.h"

namespace sbaslam::mapping {

// Projects `points` into kf and fuses them; returns the number of fusions and new observations.
int fuse_into_keyframe(map::KeyFrame* kf, const std::vector<map::MapPoint*>& points,
                       double radius = 3.0);

// `after_each_target` runs between target keyframes, where the map is consistent (local mapping
// yields the map lock there).
void search_in_neighbours(
    map::KeyFrame* kf, int neighbours, const std::function<void()>& after_each_target = [] {});

}  // namespace sbaslam::mapping
