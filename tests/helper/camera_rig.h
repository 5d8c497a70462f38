#pragma once
// A monocular 640x480 rig for tests that build keyframes by hand.

#include "sbaslam/map/map.h"

namespace sbaslam::test {

inline map::CameraRig vga_mono_rig() {
  map::CameraRig rig;
  rig.camera = PinholeCamera(PinholeIntrinsics{500.0, 500.0, 320.0, 240.0});
  rig.levels = feature::ScaleLevels::make(8, 1.2);
  rig.bounds = cv::Rect2f(0, 0, 640, 480);
  rig.stereo = false;
  return rig;
}

}  // namespace sbaslam::test
