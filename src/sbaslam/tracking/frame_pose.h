#pragma once
// Motion-only BA of a frame against its matched map points: the frame's pose is refined in place
// and its outlier flags set.

#include "sbaslam/map/measurements.h"
#include "sbaslam/optimize/map_observation.h"
#include "sbaslam/optimize/pose_optimizer.h"
#include "sbaslam/tracking/frame.h"

namespace sbaslam::tracking {

// Returns the number of inlier matches after optimisation.
int optimize_frame_pose(Frame& frame, const map::CameraRig& rig);

}  // namespace sbaslam::tracking
