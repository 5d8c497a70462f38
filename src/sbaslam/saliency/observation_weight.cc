#include "sbaslam/saliency/observation_weight.h"

#include <algorithm>
#include <utility>

namespace sbaslam::saliency {

namespace {

float saliency_at(const cv::Mat& saliency_map, float sx, float sy, const feature::OrbKeypoint& kp) {
  const int x = std::clamp(static_cast<int>(kp.x * sx), 0, saliency_map.cols - 1);
  const int y = std::clamp(static_cast<int>(kp.y * sy), 0, saliency_map.rows - 1);
  return saliency_map.at<std::uint8_t>(y, x) / 255.0f;
}

}  // namespace

float point_depth_weight(float s_init, double z, double near, const SaliencySettings& settings) {
  const double a = settings.depth_a, b = settings.depth_b;
  const double s = (a * s_init / std::max(z, near) + b) / (a / near + b);
  return observation_weight(static_cast<float>(std::clamp(s, 0.0, 1.0)), settings);
}

std::vector<float> keypoint_saliency(const cv::Mat& saliency_map, const cv::Size& image_size,
                                     const std::vector<feature::OrbKeypoint>& keypoints) {
  if (saliency_map.empty()) return {};
  CV_Assert(saliency_map.type() == CV_8UC1);
  const float sx = static_cast<float>(saliency_map.cols) / static_cast<float>(image_size.width);
  const float sy = static_cast<float>(saliency_map.rows) / static_cast<float>(image_size.height);
  std::vector<float> s(keypoints.size());
  for (std::size_t i = 0; i < keypoints.size(); ++i)
    s[i] = saliency_at(saliency_map, sx, sy, keypoints[i]);
  return s;
}

std::vector<float> keypoint_weights(const cv::Mat& saliency_map, const cv::Size& image_size,
                                    const std::vector<feature::OrbKeypoint>& keypoints,
                                    const SaliencySettings& settings) {
  if (saliency_map.empty()) return std::vector<float>(keypoints.size(), 1.0f);
  std::vector<float> weights = keypoint_saliency(saliency_map, image_size, keypoints);
  for (float& w : weights) w = observation_weight(w, settings);
  return weights;
}

std::vector<bool> salient_keypoints(const cv::Mat& saliency_map, const cv::Size& image_size,
                                    const std::vector<feature::OrbKeypoint>& keypoints,
                                    double floor, double max_dropped_share) {
  std::vector<bool> keep(keypoints.size(), true);
  if (saliency_map.empty() || floor <= 0.0) return keep;
  CV_Assert(saliency_map.type() == CV_8UC1);
  const float sx = static_cast<float>(saliency_map.cols) / static_cast<float>(image_size.width);
  const float sy = static_cast<float>(saliency_map.rows) / static_cast<float>(image_size.height);
  std::vector<std::pair<float, std::size_t>> below;
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const float s = saliency_at(saliency_map, sx, sy, keypoints[i]);
    if (s < floor) below.emplace_back(s, i);
  }
  // Ties broken by index, so that the choice does not depend on the sort's implementation.
  std::sort(below.begin(), below.end());
  const auto most = static_cast<std::size_t>(max_dropped_share * keypoints.size());
  for (std::size_t k = 0; k < std::min(most, below.size()); ++k) keep[below[k].second] = false;
  return keep;
}

}  // namespace sbaslam::saliency
