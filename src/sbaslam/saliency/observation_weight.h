#pragma once
// The one place that computes an observation's Salient BA weight, w = a * S(x, y)^2 + b, with S
// the saliency map's value at the keypoint's level-0 image position, normalised to [0, 1].
// Motion-only, local and global BA read the weight stored with each keypoint, except that local
// and global BA recompute it from the keypoint's stored S_init and its point's depth when
// Saliency.map_ba_depth asks (point_depth_weight); none of them reads a saliency map.

#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"

namespace sbaslam::saliency {

// Weight of one saliency value s in [0, 1].
inline float observation_weight(float s, const SaliencySettings& settings) {
  return static_cast<float>(settings.weight_a * s * s + settings.weight_b);
}

// Saliency.map_ba_depth: "point": Algorithm 1 for one observation, with D the point's own depth z
// in its keyframe: s = (depth_a * s_init / max(z, near) + depth_b) / (depth_a / near + depth_b),
// the divisor being the largest value an observation of the keyframe can take, and w = a s^2 + b.
// With depth_a = 1, depth_b = 0 this is s_init * min(1, near / z), what the frame's map gives at a
// keypoint whose densified depth is z. near must be > 0.
float point_depth_weight(float s_init, double z, double near, const SaliencySettings& settings);

// The saliency map's value at each keypoint, in [0, 1] (nearest pixel of the map scaled to the
// image); empty for an empty map.
std::vector<float> keypoint_saliency(const cv::Mat& saliency_map, const cv::Size& image_size,
                                     const std::vector<feature::OrbKeypoint>& keypoints);

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
