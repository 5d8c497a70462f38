#pragma once
// What the front end measured in one image (or stereo pair). A Frame and the KeyFrame made from
// it share one immutable copy; nothing writes it after the front end.

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/match/feature_grid.h"

namespace sbaslam::map {

// The rig seen by tracking and mapping: an undistorting pinhole camera and, for stereo, the
// rectified baseline. th_depth separates close stereo points (triangulated from one frame) from
// far ones (ORB-SLAM's mThDepth, in metres).
struct CameraRig {
  PinholeCamera camera;
  double bf = 0.0;
  double th_depth = 0.0;
  // Keypoints carry a depth and a right-image column: from a stereo pair, or with `rgbd` from a
  // registered depth image (ORB-SLAM3's virtual right column u - bf / d).
  bool stereo = false;
  bool rgbd = false;
  int width = 0;
  int height = 0;
  cv::Rect2f bounds;  // undistorted image bounds
  feature::ScaleLevels levels;

  double fx() const { return camera.intrinsics().fx; }
  double baseline() const { return stereo ? bf / fx() : 0.0; }
  bool in_image(const Vec2& uv) const {
    return uv.x() >= bounds.x && uv.x() < bounds.x + bounds.width && uv.y() >= bounds.y &&
           uv.y() < bounds.y + bounds.height;
  }
};

struct Measurements {
  std::vector<feature::OrbKeypoint> keypoints;     // as detected (distorted pixels)
  std::vector<feature::OrbKeypoint> keypoints_un;  // undistorted pixels
  cv::Mat descriptors;                             // one 32-byte row per keypoint
  std::vector<float> u_right;                      // right-image column, or -1
  std::vector<float> depth;                        // metres from stereo/RGB-D, or -1
  std::vector<float> weights;                      // BA weight per keypoint (saliency)
  match::FeatureGrid grid;                         // over keypoints_un, for radius queries
  // Saturated S_init per keypoint, in [0, 1], kept where local and full BA recompute the weights
  // from each point's depth (SaliencySettings::map_ba_depth); otherwise empty.
  std::vector<float> s_init;

  std::size_t size() const { return keypoints.size(); }
  const std::uint8_t* descriptor(std::size_t i) const {
    return descriptors.ptr<std::uint8_t>(static_cast<int>(i));
  }
};

using MeasurementsPtr = std::shared_ptr<const Measurements>;

}  // namespace sbaslam::map
