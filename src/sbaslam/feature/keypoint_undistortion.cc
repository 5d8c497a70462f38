#include "sbaslam/feature/keypoint_undistortion.h"

#include <algorithm>
#include <limits>

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

namespace {

// A fisheye image's undistorted extremes can lie anywhere on its border (where rays reach the
// field limit), not only at its corners.
cv::Rect2f fisheye_image_bounds(const PinholeCamera& camera, double w, double h) {
  constexpr int kSamplesPerEdge = 256;
  double min_x = std::numeric_limits<double>::infinity(), min_y = min_x;
  double max_x = -min_x, max_y = -min_x;
  for (int i = 0; i <= kSamplesPerEdge; ++i) {
    const double s = static_cast<double>(i) / kSamplesPerEdge;
    for (const Vec2& raw : {Vec2(s * w, 0.0), Vec2(s * w, h), Vec2(0.0, s * h), Vec2(w, s * h)}) {
      const Vec2 uv = camera.undistort_within_field(raw);
      min_x = std::min(min_x, uv.x());
      max_x = std::max(max_x, uv.x());
      min_y = std::min(min_y, uv.y());
      max_y = std::max(max_y, uv.y());
    }
  }
  return {static_cast<float>(min_x), static_cast<float>(min_y), static_cast<float>(max_x - min_x),
          static_cast<float>(max_y - min_y)};
}

}  // namespace

cv::Rect2f undistorted_image_bounds(const PinholeCamera& camera, int width, int height) {
  const auto w = static_cast<float>(width), h = static_cast<float>(height);
  if (!camera.has_distortion()) return {0.0f, 0.0f, w, h};
  if (camera.is_fisheye()) return fisheye_image_bounds(camera, w, h);
  const Vec2 corners[4] = {camera.undistort(Vec2(0.0, 0.0)), camera.undistort(Vec2(w, 0.0)),
                           camera.undistort(Vec2(0.0, h)), camera.undistort(Vec2(w, h))};
  // As ORB-SLAM: the left edge from the left corners, the top edge from the top corners, etc.
  const float min_x = static_cast<float>(std::min(corners[0].x(), corners[2].x()));
  const float max_x = static_cast<float>(std::max(corners[1].x(), corners[3].x()));
  const float min_y = static_cast<float>(std::min(corners[0].y(), corners[1].y()));
  const float max_y = static_cast<float>(std::max(corners[2].y(), corners[3].y()));
  return {min_x, min_y, max_x - min_x, max_y - min_y};
}

void drop_keypoints_beyond_field(const PinholeCamera& camera, std::vector<OrbKeypoint>& keypoints,
                                 cv::Mat& descriptors) {
  if (!camera.is_fisheye()) return;
  std::vector<OrbKeypoint> kept;
  cv::Mat kept_descriptors;
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    if (!camera.sees_on_pinhole_plane(Vec2(keypoints[i].x, keypoints[i].y))) continue;
    kept.push_back(keypoints[i]);
    kept_descriptors.push_back(descriptors.row(static_cast<int>(i)));
  }
  keypoints = std::move(kept);
  descriptors = kept_descriptors.empty() ? cv::Mat(0, descriptors.cols, descriptors.type())
                                         : kept_descriptors;
}

}  // namespace sbaslam::feature
