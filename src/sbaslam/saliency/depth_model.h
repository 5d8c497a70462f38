#pragma once
// A user-supplied monocular depth network in ONNX, run through OpenCV dnn: the D of Algorithm 1
// the paper takes from MonoDepth. The grey image is resized to the network's input (INTER_AREA),
// scaled to [0, 1] and copied to three channels when the network wants RGB; the single-channel
// output is turned into depth (1 / value for inverse-depth networks). Values that give no
// positive finite depth are 0, which Algorithm 1 treats as invalid.

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <string>

#include "sbaslam/core/settings.h"

namespace sbaslam::saliency {

class DepthModel {
 public:
  // Fails with a message naming the file when it is missing or not a readable ONNX model.
  explicit DepthModel(const DepthModelSettings& settings);

  // CV_32F depth at the network's output size, from an 8-bit grey image.
  cv::Mat predict(const cv::Mat& gray);

 private:
  DepthModelSettings settings_;
  cv::dnn::Net net_;
};

}  // namespace sbaslam::saliency
