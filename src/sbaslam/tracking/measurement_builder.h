#pragma once
// The front end of one frame: ORB extraction (both images of a stereo pair in parallel), stereo
// matching or RGB-D depth, undistorted keypoints, the keypoint grid and the Salient BA weight of
// every keypoint. Its output is immutable and shared by the frame and its keyframe.

#include <functional>
#include <memory>
#include <opencv2/core.hpp>

#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/map/measurements.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/saliency/depth_model.h"

namespace sbaslam::tracking {

// A frame's measurements before their Salient BA weights: what extraction gives.
struct ExtractedFrame {
  std::shared_ptr<map::Measurements> measurements;  // still writable: weigh() adds the weights
  cv::Mat depth_metres;  // RGB-D rigs: the depth image in metres, for the depth correction
};

class MeasurementBuilder {
 public:
  MeasurementBuilder(const map::CameraRig& rig, const OrbSettings& orb,
                     const SaliencySettings& saliency, const RgbdSettings& rgbd = {});

  // `right` is used for a stereo rig and ignored otherwise; `depth_image` (raw values, metres =
  // value / DepthMapFactor, 0 = none) is needed for an RGB-D rig and ignored otherwise.
  // `saliency_map` may be empty (uniform). `depth_samples`: depth samples for Algorithm 1: a
  // monocular frame's predicted map depths (Tracker::predicted_point_depths), or any frame's
  // velodyne scan (Saliency.depth "velodyne"); a stereo frame otherwise uses its own matches and
  // an RGB-D frame its depth image.
  map::MeasurementsPtr build(const cv::Mat& left, const cv::Mat& right, const cv::Mat& saliency_map,
                             const std::vector<saliency::DepthSample>& depth_samples = {},
                             const cv::Mat& depth_image = cv::Mat());

  // build() in two steps, so that the saliency map can be predicted while extraction runs:
  // extract() needs no saliency; weigh() sets every keypoint's weight from the map (arguments as
  // for build()). `beside` (optional) runs among the extraction's parallel tasks.
  ExtractedFrame extract(const cv::Mat& left, const cv::Mat& right,
                         const cv::Mat& depth_image = cv::Mat(),
                         const std::function<void()>& beside = {});
  void weigh(ExtractedFrame& frame, const cv::Mat& left, const cv::Mat& saliency_map,
             const std::vector<saliency::DepthSample>& depth_samples = {});

  const map::CameraRig& rig() const { return rig_; }

 private:
  // Algorithm 1's depth correction of the frame's saturated map `s_init` (D from the depth model;
  // velodyne or monocular: from `depth_samples`; otherwise RGB-D: from `depth_metres`, stereo: from
  // its matches), or the map unchanged without depth.
  cv::Mat corrected_saliency(const cv::Mat& s_init, const cv::Mat& left, const map::Measurements& m,
                             const std::vector<saliency::DepthSample>& depth_samples,
                             const cv::Mat& depth_metres);
  // ORB-SLAM3's RGB-D keypoints: the depth at the detected (distorted) pixel, and a virtual right
  // column u_un - bf / d, so that tracking and mapping treat them as stereo points.
  void add_rgbd_depths(map::Measurements& m, const cv::Mat& depth_metres) const;
  // Removes the keypoints whose `keep` is false from every per-keypoint field and the grid.
  void keep_keypoints(map::Measurements& m, const std::vector<bool>& keep) const;

  map::CameraRig rig_;
  SaliencySettings saliency_;
  RgbdSettings rgbd_;
  std::unique_ptr<saliency::DepthModel> depth_model_;  // loaded at first use
  std::unique_ptr<feature::OrbExtractor> mono_;
  std::unique_ptr<feature::StereoExtractor> stereo_;
  feature::StereoFeatures stereo_features_;
};

// Builds the rig from the settings: undistorted bounds, scale levels and stereo parameters.
// With `rgbd` the depth comes from a depth image and `stereo` gives the virtual baseline.
map::CameraRig make_camera_rig(const CameraSettings& camera, const StereoSettings& stereo,
                               const OrbSettings& orb, bool use_stereo, bool rgbd = false);

}  // namespace sbaslam::tracking
