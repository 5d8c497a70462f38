#pragma once
// Reads an EuRoC (ASL) camera sensor.yaml: intrinsics, radial-tangential distortion, resolution,
// rate and T_BS, the pose of the sensor in the body (IMU) frame.

#include <string>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"

namespace sbaslam::io {

struct EurocCameraSensor {
  CameraSettings camera;
  SE3 T_BS;  // maps sensor-frame points into the body frame
};

// Throws sbaslam::Error naming the file and the key on anything missing or invalid.
EurocCameraSensor read_euroc_camera_sensor(const std::string& sensor_yaml);

}  // namespace sbaslam::io
