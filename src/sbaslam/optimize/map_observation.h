#pragma once
// BA inputs taken from the map's measurements: the rectified camera of a rig, and the observation
// of one keypoint (undistorted pixel, right column for stereo, its level's information and its
// Salient BA weight). Motion-only, local and global BA all build observations here.

#include "sbaslam/map/measurements.h"
#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

inline RectifiedCamera rectified_camera(const map::CameraRig& rig) {
  const PinholeIntrinsics& k = rig.camera.intrinsics();
  return {k.fx, k.fy, k.cx, k.cy, rig.bf};
}

inline PixelObservation observation_of(const map::Measurements& m, std::size_t i,
                                       const map::CameraRig& rig) {
  const feature::OrbKeypoint& kp = m.keypoints_un[i];
  PixelObservation obs;
  obs.u = kp.x;
  obs.v = kp.y;
  obs.u_right = rig.stereo ? m.u_right[i] : -1.0;
  obs.inv_sigma2 = rig.levels.inv_sigma2[static_cast<std::size_t>(kp.octave)];
  obs.weight = m.weights[i];
  return obs;
}

}  // namespace sbaslam::optimize
