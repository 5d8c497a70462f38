#pragma once
// Algorithm 1's D from KITTI velodyne scans. A frame's scan lies next to its image, as the
// odometry dataset unpacks: <sequence>/image_0/<stem>.png has <sequence>/velodyne/<stem>.bin, and
// <sequence>/calib.txt's Tr moves scanner points into the left camera. The scan is projected with
// the rectified left camera; points behind it, nearer than min_depth or outside the image drop.
// The samples are then densified like monocular map depths (depth_correction.h).

#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/io/velodyne_scan.h"
#include "sbaslam/saliency/depth_correction.h"

namespace sbaslam::saliency {

std::vector<DepthSample> project_scan(const std::vector<io::VelodynePoint>& scan,
                                      const SE3& T_camera_velodyne, const PinholeIntrinsics& k,
                                      const cv::Size& image_size, double min_depth = 1.0);

class VelodyneDepth {
 public:
  VelodyneDepth(const PinholeIntrinsics& k, const cv::Size& image_size);

  // The projected scan of the frame whose left image is `left_image_path`. Throws sbaslam::Error
  // naming the file when the scan or calib.txt's Tr row is missing or malformed.
  std::vector<DepthSample> samples_for(const std::string& left_image_path);

 private:
  const SE3& camera_from_velodyne(const std::filesystem::path& sequence_dir);

  PinholeIntrinsics k_;
  cv::Size image_size_;
  std::map<std::filesystem::path, SE3> calibration_;  // per sequence folder
};

}  // namespace sbaslam::saliency
