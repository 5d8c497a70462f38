#pragma once
// Where a frame's saliency map comes from: nothing (uniform BA), the shipped DI-Net-style ONNX
// model run with OpenCV dnn, or a folder of precomputed maps named like the input images (the way
// the paper and Salient-DSO feed their maps to the SLAM system).

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "sbaslam/core/settings.h"

namespace sbaslam::saliency {

class SaliencySource {
 public:
  virtual ~SaliencySource();
  // 8-bit map of the left image (any size; keypoint_weights scales it); empty = uniform weights.
  virtual cv::Mat predict(const cv::Mat& left_gray, double timestamp,
                          const std::string& left_path) = 0;
};

// "none": every map is empty, so every BA weight is 1 (plain ORB-SLAM3 BA).
class UniformSaliency : public SaliencySource {
 public:
  cv::Mat predict(const cv::Mat&, double, const std::string&) override { return {}; }
};

// Reads "<folder>/<file name of left_path>" (or the same stem with .png). A missing or unreadable
// map is an error naming the map and the image.
class PrecomputedSaliency : public SaliencySource {
 public:
  explicit PrecomputedSaliency(std::string folder);
  cv::Mat predict(const cv::Mat& left_gray, double timestamp,
                  const std::string& left_path) override;

 private:
  std::string folder_;
};

// The ONNX file `--saliency model` runs (Saliency.model, or the shipped model); empty for the
// other sources. run.json records it.
std::string saliency_model_file(const std::string& spec, const SaliencySettings& settings);

// Never null. spec: "none" | "model" (the shipped ONNX, or SaliencySettings::model_path when set) |
// a folder of precomputed saliency PNGs named like the input images. Anything else is an error.
std::unique_ptr<SaliencySource> make_saliency_source(const std::string& spec,
                                                     const SaliencySettings& settings);

}  // namespace sbaslam::saliency
