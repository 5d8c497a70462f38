#pragma once
// ORB-SLAM2's stereo settings layout (its Examples/Stereo/EuRoC.yaml): Camera.* for the rectified
// images, Camera.bf, and the precomputed rectification in LEFT.* / RIGHT.*, made here for the
// EuRoC fixture's rig the way a user's own calibration script would make it.

#include <string>

#include "sbaslam/core/settings.h"

namespace sbaslam::test {

// cv::stereoRectify (CALIB_ZERO_DISPARITY, the given alpha) of the fixture's two sensor.yaml
// cameras. Alpha 0 is what sba-slam's own rectifier uses.
PrecomputedRectification euroc_fixture_rectification(double alpha);

// A whole settings file in ORB-SLAM2's layout for that rectification, with its quirks kept
// (a "data:[" without a space, Viewer keys, Camera.bFishEye).
std::string orbslam2_stereo_settings(const PrecomputedRectification& rectification);

}  // namespace sbaslam::test
