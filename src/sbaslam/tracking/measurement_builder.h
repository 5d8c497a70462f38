#pragma once
// The front end of one frame: ORB extraction (both images of a stereo pair in parallel), stereo
// matching or RGB-D depth, undistorted keypoints, the keypoint grid and the Salient BA weight of
// every keypoint. Its output is immutable and shared by the frame and its keyframe.

#include <memory>
#include <opencv2/core.hpp>

#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/map/measurements.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/saliency/depth_model.h"

namespace sbaslam::tracking {

class MeasurementBuilder {
 public:
  MeasurementBuilder(const map::CameraRig& rig, const OrbSettings& orb,
                     const SaliencySettings& saliency);

  // `right` is used for a stereo rig and ignored otherwise. `saliency_map` may be empty (uniform).
  // `depth_samples`: depth samples for Algorithm 1: a monocular frame's predicted map depths
  // (Tracker::predicted_point_depths), or any frame's velodyne scan (Saliency.depth "velodyne");
  // a stereo frame otherwise uses its own matches.
  map::MeasurementsPtr build(const cv::Mat& left, const cv::Mat& right, const cv::Mat& saliency_map,
                             const std::vector<saliency::DepthSample>& depth_samples = {});

  const map::CameraRig& rig() const { return rig_; }

 private:
  // Algorithm 1's depth correction of the frame's map (D from the depth model; velodyne or
  // monocular: from `depth_samples`; otherwise stereo: from its matches), or the map unchanged
  // without depth.
  cv::Mat corrected_saliency(const cv::Mat& s_init, const cv::Mat& left, const map::Measurements& m,
                             const std::vector<saliency::DepthSample>& depth_samples);

  map::CameraRig rig_;
  SaliencySettings saliency_;
  std::unique_ptr<saliency::DepthModel> depth_model_;  // loaded at first use
  std::unique_ptr<feature::OrbExtractor> mono_;
  std::unique_ptr<feature::StereoExtractor> stereo_;
  feature::StereoFeatures stereo_features_;
};

// Builds the rig from the settings: undistorted bounds, scale levels and stereo parameters.
map::CameraRig make_camera_rig(const CameraSettings& camera, const StereoSettings& stereo,
                               const OrbSettings& orb, bool use_stereo);

}  // namespace sbaslam::tracking
