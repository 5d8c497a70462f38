#include "sbaslam/saliency/observation_weight.h"

#include <algorithm>

namespace sbaslam::saliency {

std::vector<float> keypoint_weights(const cv::Mat& saliency_map, const cv::Size& image_size,
                                    const std::vector<feature::OrbKeypoint>& keypoints,
                                    const SaliencySettings& settings) {
  std::vector<float> weights(keypoints.size(), 1.0f);
  if (saliency_map.empty()) return weights;
  CV_Assert(saliency_map.type() == CV_8UC1);
  const float sx = static_cast<float>(saliency_map.cols) / static_cast<float>(image_size.width);
  const float sy = static_cast<float>(saliency_map.rows) / static_cast<float>(image_size.height);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const int x = std::clamp(static_cast<int>(keypoints[i].x * sx), 0, saliency_map.cols - 1);
    const int y = std::clamp(static_cast<int>(keypoints[i].y * sy), 0, saliency_map.rows - 1);
    const float s = saliency_map.at<std::uint8_t>(y, x) / 255.0f;
    weights[i] = observation_weight(s, settings);
  }
  return weights;
}

}  // namespace sbaslam::saliency
