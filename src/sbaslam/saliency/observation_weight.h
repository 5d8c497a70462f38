#pragma once
// The one place that computes an observation's Salient BA weight, w = a * S(x, y)^2 + b, with S
// the saliency map's value at the keypoint's level-0 image position, normalised to [0, 1].
// Motion-only, local and global BA read the weight stored with each keypoint; none of them reads a
// saliency map.

#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::saliency {

// Weight of one saliency value s in [0, 1].
inline float observation_weight(float s, const SaliencySettings& settings) {
  return static_cast<float>(settings.weight_a * s * s + settings.weight_b);
}

// One weight per keypoint, sampled from an 8-bit saliency map of the raw image (any size: it is
// scaled to the image). An empty map means uniform BA: every weight is 1.
std::vector<float> keypoint_weights(const cv::Mat& saliency_map, const cv::Size& image_size,
                                    const std::vector<feature::OrbKeypoint>& keypoints,
                                    const SaliencySettings& settings);

// Which keypoints to keep when extraction is guided by saliency (Saliency.keypoint_floor): those
// whose map value, normalised to [0, 1], is at least `floor`. At most `max_dropped_share` of the
// keypoints go, the least salient first, so that a frame filled by a moving object keeps enough
// to track. An empty map or a floor of 0 keeps every keypoint.
std::vector<bool> salient_keypoints(const cv::Mat& saliency_map, const cv::Size& image_size,
                                    const std::vector<feature::OrbKeypoint>& keypoints,
                                    double floor, double max_dropped_share);

}  // namespace sbaslam::saliency
