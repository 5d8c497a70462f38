#pragma once
// Synthetic KITTI velodyne scans for the KITTI-layout scenes, so that the velodyne depth source
// (saliency/velodyne_depth.h) can be run end to end. A scan is the rendered left-camera depth read
// along the rows of a 64-beam scanner's elevations (+2 to -24.8 degrees, as an HDL-64E), every
// second pixel, and written in the scanner's frame (x forward, y left, z up). The scanner sits
// where KITTI's is relative to cam0 (kCameraFromVelodyne). It sees only what the camera sees: no
// points outside the image, and no occlusion from its own viewpoint.

#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/io/velodyne_scan.h"
#include "sbaslam/sim/renderer.h"

namespace sbaslam::sim {

// T_cam0_velodyne, KITTI's axes and a lever arm close to its odometry calibration's: the scanner
// 8 cm above and 27 cm behind the left camera. Written as calib.txt's Tr.
SE3 camera_from_velodyne();

// depth: CV_32F metres in the left camera (0: nothing hit).
std::vector<io::VelodynePoint> sample_velodyne_scan(const cv::Mat& depth, const ViewCamera& camera);

}  // namespace sbaslam::sim
