#include "sbaslam/tracking/measurement_builder.h"

#include "sbaslam/feature/keypoint_undistortion.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/saliency/observation_weight.h"

namespace sbaslam::tracking {

map::CameraRig make_camera_rig(const CameraSettings& camera, const StereoSettings& stereo,
                               const OrbSettings& orb, bool use_stereo) {
  map::CameraRig rig;
  rig.camera = PinholeCamera(camera);
  rig.width = camera.width;
  rig.height = camera.height;
  rig.bounds = feature::undistorted_image_bounds(rig.camera, camera.width, camera.height);
  rig.levels = feature::ScaleLevels::make(orb.n_levels, orb.scale_factor);
  rig.stereo = use_stereo;
  if (use_stereo) {
    rig.bf = stereo.bf;
    rig.th_depth = stereo.th_depth * stereo.baseline;
  }
  return rig;
}

MeasurementBuilder::MeasurementBuilder(const map::CameraRig& rig, const OrbSettings& orb,
                                       const SaliencySettings& saliency)
    : rig_(rig), saliency_(saliency) {
  if (rig_.stereo) {
    stereo_ = std::make_unique<feature::StereoExtractor>(
        orb, StereoRig(rig_.camera.intrinsics(), rig_.baseline()));
  } else {
    mono_ = std::make_unique<feature::OrbExtractor>(orb);
  }
}

cv::Mat MeasurementBuilder::corrected_saliency(
    const cv::Mat& s_init, const cv::Mat& left, const map::Measurements& m,
    const std::vector<saliency::DepthSample>& depth_samples) {
  if (s_init.empty() || saliency_.depth_source == "none") return s_init;
  if (saliency_.depth_source == "model") {
    if (!depth_model_) depth_model_ = std::make_unique<saliency::DepthModel>(saliency_.depth_model);
    return saliency::depth_corrected_saliency(s_init, depth_model_->predict(left),
                                              saliency_.depth_a, saliency_.depth_b);
  }
  std::vector<saliency::DepthSample> depths;
  if (rig_.stereo && saliency_.depth_source == "auto") {
    for (std::size_t i = 0; i < m.size(); ++i)
      if (m.depth[i] > 0.0f) depths.push_back({m.keypoints[i].x, m.keypoints[i].y, m.depth[i]});
  } else {
    depths = depth_samples;
  }
  if (depths.empty()) return s_init;
  return saliency::depth_corrected_saliency(s_init, left.size(), depths, saliency_.depth_a,
                                            saliency_.depth_b);
}

map::MeasurementsPtr MeasurementBuilder::build(
    const cv::Mat& left, const cv::Mat& right, const cv::Mat& saliency_map,
    const std::vector<saliency::DepthSample>& depth_samples) {
  auto m = std::make_shared<map::Measurements>();
  if (rig_.stereo) {
    stereo_->extract(left, right, stereo_features_);
    m->keypoints = std::move(stereo_features_.left.keypoints);
    m->descriptors = stereo_features_.left.descriptors.clone();
    m->depth = std::move(stereo_features_.matches.depth);
    m->u_right = std::move(stereo_features_.matches.u_right);
  } else {
    feature::OrbFeatures features;
    mono_->extract(left, features);
    m->keypoints = std::move(features.keypoints);
    m->descriptors = features.descriptors;
    m->depth.assign(m->keypoints.size(), -1.0f);
    m->u_right.assign(m->keypoints.size(), -1.0f);
  }
  m->keypoints_un = feature::undistort_keypoints(m->keypoints, rig_.camera);
  m->grid = match::FeatureGrid(m->keypoints_un, rig_.bounds);
  m->weights = saliency::keypoint_weights(corrected_saliency(saliency_map, left, *m, depth_samples),
                                          left.size(), m->keypoints, saliency_);
  return m;
}

}  // namespace sbaslam::tracking
