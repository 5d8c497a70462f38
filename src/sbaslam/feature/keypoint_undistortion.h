#pragma once
// Undistorted keypoints (ORB-SLAM's mvKeysUn): the points are undistorted, never the image, so
// detection and descriptors see the raw pixels.

#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::feature {

// Copies of `keypoints` with x, y moved to the undistorted pixel; without distortion a plain copy.
std::vector<OrbKeypoint> undistort_keypoints(const std::vector<OrbKeypoint>& keypoints,
                                             const PinholeCamera& camera);

// Bounds of the undistorted image (ORB-SLAM's ComputeImageBounds): the extreme undistorted x and y
// of the four corners of a width x height raw image; the whole image without distortion. A
// fisheye image's bounds come from its whole border, with rays beyond kMaxFisheyeFieldAngle
// brought back to it.
cv::Rect2f undistorted_image_bounds(const PinholeCamera& camera, int width, int height);

// Drops the keypoints (and their descriptor rows) of a fisheye camera that lie beyond
// kMaxFisheyeFieldAngle; without fisheye, nothing.
void drop_keypoints_beyond_field(const PinholeCamera& camera, std::vector<OrbKeypoint>& keypoints,
                                 cv::Mat& descriptors);

}  // namespace sbaslam::feature
