#pragma once
// Where a frame can be when it relocalises while the map is out of view (localization-only,
// stereo): near visual odometry's pose, or near the last pose if odometry failed a few frames
// ago. A street whose blocks look alike otherwise relocalises the camera a block or two away.

#include <cstddef>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/map/keyframe.h"

namespace sbaslam::tracking {

struct PosePrior {
  Vec3 centre = Vec3::Zero();  // camera centre in the map's world
  double radius = 0.0;         // map units
};

// Whether the camera pose T_cw has its centre within the prior's radius.
bool within(const PosePrior& prior, const SE3& T_cw);

// Keeps the `count` candidates whose centres are nearest the prior's, nearest first (ties in the
// given order). Relocalisation near the prior needs no far keyframe, and trying every
// place-recognition candidate on every odometry frame cost 0.4 s a frame in a city.
void keep_nearest(std::vector<map::KeyFrame*>& candidates, const PosePrior& prior,
                  std::size_t count);

}  // namespace sbaslam::tracking
