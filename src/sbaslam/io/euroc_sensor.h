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

// cam0's pose in the body (IMU) frame: T_BS of an EuRoC sensor.yaml, or IMU.T_b_c1 (Tbc in older
// files) of an ORB-SLAM3 settings file, for recordings that come without sensor.yaml (TUM-VI's
// ground truth is the IMU's). Throws sbaslam::Error naming the file when it has neither.
SE3 read_body_camera_pose(const std::string& path);

}  // namespace sbaslam::io
