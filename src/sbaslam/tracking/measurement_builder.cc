#include "sbaslam/tracking/measurement_builder.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"
#include "sbaslam/feature/keypoint_undistortion.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/saliency/observation_weight.h"

namespace sbaslam::tracking {

map::CameraRig make_camera_rig(const CameraSettings& camera, const StereoSettings& stereo,
                               const OrbSettings& orb, bool use_stereo, bool rgbd) {
  map::CameraRig rig;
  rig.camera = PinholeCamera(camera);
  rig.width = camera.width;
  rig.height = camera.height;
  rig.bounds = feature::undistorted_image_bounds(rig.camera, camera.width, camera.height);
  rig.levels = feature::ScaleLevels::make(orb.n_levels, orb.scale_factor);
  rig.stereo = use_stereo || rgbd;
  rig.rgbd = rgbd;
  if (rig.stereo) {
    rig.bf = stereo.bf;
    rig.th_depth = stereo.th_depth * stereo.baseline;
  }
  return rig;
}

MeasurementBuilder::MeasurementBuilder(const map::CameraRig& rig, const OrbSettings& orb,
                                       const SaliencySettings& saliency, const RgbdSettings& rgbd)
    : rig_(rig), saliency_(saliency), rgbd_(rgbd) {
  if (rig_.stereo && !rig_.rgbd) {
    stereo_ = std::make_unique<feature::StereoExtractor>(
        orb, StereoRig(rig_.camera.intrinsics(), rig_.baseline()));
  } else {
    mono_ = std::make_unique<feature::OrbExtractor>(orb);
  }
}

cv::Mat MeasurementBuilder::corrected_saliency(
    const cv::Mat& s_init, const cv::Mat& left, const map::Measurements& m,
    const std::vector<saliency::DepthSample>& depth_samples, const cv::Mat& depth_metres) {
  if (s_init.empty()) return s_init;
  if (saliency_.depth_source == "none") return s_init;
  const double a = saliency_.depth_a, b = saliency_.depth_b;
  // For a dense depth (the RGB-D image, a depth network): the rig's threshold; a monocular
  // network's depth has no known scale, so no floor there.
  const double near = saliency_.depth_near.value_or(rig_.stereo ? rig_.th_depth : 0.0);
  if (rig_.rgbd && saliency_.depth_source == "auto")
    return saliency::depth_corrected_saliency(s_init, depth_metres, a, b, near);
  if (saliency_.depth_source == "model") {
    if (!depth_model_) depth_model_ = std::make_unique<saliency::DepthModel>(saliency_.depth_model);
    return saliency::depth_corrected_saliency(s_init, depth_model_->predict(left), a, b, near);
  }
  std::vector<saliency::DepthSample> depths;
  if (rig_.stereo && !rig_.rgbd && saliency_.depth_source == "auto") {
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m.depth[i] > 0.0f) depths.push_back({m.keypoints[i].x, m.keypoints[i].y, m.depth[i]});
  } else {
    depths = depth_samples;
  }
  if (depths.empty()) return s_init;
  // A monocular map has no metric scale, so "auto" floors D at the samples' median depth (a
  // velodyne scan's too), a scale-free stand-in for the stereo close-point threshold, which lies
  // near the median on the city renders.
  const double sample_near = saliency_.depth_near.value_or(
      rig_.stereo ? rig_.th_depth : saliency::median_sample_depth(depths));
  return saliency::depth_corrected_saliency(s_init, left.size(), depths, a, b, sample_near);
}

map::MeasurementsPtr MeasurementBuilder::build(
    const cv::Mat& left, const cv::Mat& right, const cv::Mat& saliency_map,
    const std::vector<saliency::DepthSample>& depth_samples, const cv::Mat& depth_image) {
  ExtractedFrame frame = extract(left, right, depth_image);
  weigh(frame, left, saliency_map, depth_samples);
  return frame.measurements;
}

ExtractedFrame MeasurementBuilder::extract(const cv::Mat& left, const cv::Mat& right,
                                           const cv::Mat& depth_image,
                                           const std::function<void()>& beside) {
  ExtractedFrame frame;
  frame.measurements = std::make_shared<map::Measurements>();
  map::Measurements& m = *frame.measurements;
  if (rig_.stereo && !rig_.rgbd) {
    stereo_->extract(left, right, stereo_features_, beside);
    m.keypoints = std::move(stereo_features_.left.keypoints);
    m.descriptors = stereo_features_.left.descriptors.clone();
    m.depth = std::move(stereo_features_.matches.depth);
    m.u_right = std::move(stereo_features_.matches.u_right);
  } else {
    feature::OrbFeatures features;
    mono_->extract_sharing_cores(left, features, beside);
    m.keypoints = std::move(features.keypoints);
    m.descriptors = features.descriptors;
    feature::drop_keypoints_beyond_field(rig_.camera, m.keypoints, m.descriptors);
    m.depth.assign(m.keypoints.size(), -1.0f);
    m.u_right.assign(m.keypoints.size(), -1.0f);
  }
  m.keypoints_un = feature::undistort_keypoints(m.keypoints, rig_.camera);
  if (rig_.rgbd) {
    if (depth_image.size() != left.size())
      fail("RGB-D frame: the depth image is {}x{}, the image {}x{}", depth_image.cols,
           depth_image.rows, left.cols, left.rows);
    frame.depth_metres = saliency::rgbd_depth(depth_image, rgbd_.depth_map_factor);
    add_rgbd_depths(m, frame.depth_metres);
  }
  m.grid = match::FeatureGrid(m.keypoints_un, rig_.bounds);
  return frame;
}

void MeasurementBuilder::weigh(ExtractedFrame& frame, const cv::Mat& left,
                               const cv::Mat& saliency_map,
                               const std::vector<saliency::DepthSample>& depth_samples) {
  map::Measurements& m = *frame.measurements;
  const cv::Mat s_init = saliency_map.empty()
                             ? saliency_map
                             : saliency::saturated_saliency(saliency_map, saliency_.saturation);
  m.weights = saliency::keypoint_weights(
      corrected_saliency(s_init, left, m, depth_samples, frame.depth_metres), left.size(),
      m.keypoints, saliency_);
  if (saliency_.map_ba_point_depth(rig_.stereo))
    m.s_init = saliency::keypoint_saliency(s_init, left.size(), m.keypoints);
  if (saliency_.keypoint_floor > 0.0 && !s_init.empty()) {
    // Guided by S_init rather than the depth-corrected map, which is low on far static structure.
    const std::vector<bool> keep =
        saliency::salient_keypoints(s_init, left.size(), m.keypoints, saliency_.keypoint_floor,
                                    saliency_.keypoint_max_dropped_share);
    keep_keypoints(m, keep);
  }
}

void MeasurementBuilder::keep_keypoints(map::Measurements& m, const std::vector<bool>& keep) const {
  const auto kept = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), true));
  if (kept == keep.size()) return;
  cv::Mat descriptors(static_cast<int>(kept), m.descriptors.cols, m.descriptors.type());
  std::size_t k = 0;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    m.keypoints[k] = m.keypoints[i];
    m.keypoints_un[k] = m.keypoints_un[i];
    m.u_right[k] = m.u_right[i];
    m.depth[k] = m.depth[i];
    m.weights[k] = m.weights[i];
    if (!m.s_init.empty()) m.s_init[k] = m.s_init[i];
    m.descriptors.row(static_cast<int>(i)).copyTo(descriptors.row(static_cast<int>(k)));
    ++k;
  }
  m.keypoints.resize(kept);
  m.keypoints_un.resize(kept);
  m.u_right.resize(kept);
  m.depth.resize(kept);
  m.weights.resize(kept);
  if (!m.s_init.empty()) m.s_init.resize(kept);
  m.descriptors = descriptors;
  m.grid = match::FeatureGrid(m.keypoints_un, rig_.bounds);
}

void MeasurementBuilder::add_rgbd_depths(map::Measurements& m, const cv::Mat& depth_metres) const {
  for (std::size_t i = 0; i < m.keypoints.size(); ++i) {
    const int x = static_cast<int>(std::lround(m.keypoints[i].x));
    const int y = static_cast<int>(std::lround(m.keypoints[i].y));
    if (x < 0 || y < 0 || x >= depth_metres.cols || y >= depth_metres.rows) continue;
    const float d = depth_metres.at<float>(y, x);
    if (!(d > 0.0f) || !std::isfinite(d)) continue;
    m.depth[i] = d;
    m.u_right[i] = static_cast<float>(m.keypoints_un[i].x - rig_.bf / d);
  }
}

}  // namespace sbaslam::tracking
