#include "sbaslam/feature/keypoint_undistortion.h"

#include <algorithm>

namespace sbaslam::feature {

std::vector<OrbKeypoint> undistort_keypoints(const std::vector<OrbKeypoint>& keypoints,
                                             const PinholeCamera& camera) {
  std::vector<OrbKeypoint> undistorted = keypoints;
  if (!camera.has_distortion()) return undistorted;
  for (OrbKeypoint& kp : undistorted) {
    const Vec2 uv = camera.undistort(Vec2(kp.x, kp.y));
    kp.x = static_cast<float>(uv.x());
    kp.y = static_cast<float>(uv.y());
  }
  return undistorted;
}

cv::Rect2f undistorted_image_bounds(const PinholeCamera& camera, int width, int height) {
  const auto w = static_cast<float>(width), h = static_cast<float>(height);
  if (!camera.has_distortion()) return {0.0f, 0.0f, w, h};
  const Vec2 corners[4] = {camera.undistort(Vec2(0.0, 0.0)), camera.undistort(Vec2(w, 0.0)),
                           camera.undistort(Vec2(0.0, h)), camera.undistort(Vec2(w, h))};
  // As ORB-SLAM: the left edge from the left corners, the top edge from the top corners, etc.
  const float min_x = static_cast<float>(std::min(corners[0].x(), corners[2].x()));
  const float max_x = static_cast<float>(std::max(corners[1].x(), corners[3].x()));
  const float min_y = static_cast<float>(std::min(corners[0].y(), corners[1].y()));
  const float max_y = static_cast<float>(std::max(corners[2].y(), corners[3].y()));
  return {min_x, min_y, max_x - min_x, max_y - min_y};
}

}  // namespace sbaslam::feature
