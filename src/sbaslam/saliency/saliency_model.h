#pragma once
// The DI-Net-style saliency network (python/train_saliency.py) run through OpenCV dnn on the CPU.
// The ONNX file has a fixed input size, read from the JSON card beside it (<model>.json:
// {"input_size": [w, h]}); the grayscale frame is resized to it (INTER_AREA), scaled to [0, 1],
// and the network's per-pixel logits z become the 8-bit map 255 * exp(z - max z), i.e. the
// predicted fixation density with its peak at 255.

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <string>

#include "sbaslam/saliency/saliency_source.h"

namespace sbaslam::saliency {

// Where the shipped model is looked for: $SBASLAM_MODEL_DIR, then the installed share folder,
// then the source tree's models/. Throws when it is in none of them.
std::string shipped_model_path();

class SaliencyModel : public SaliencySource {
 public:
  // Throws sbaslam::Error naming the file when the model or its JSON card is missing or corrupt.
  explicit SaliencyModel(const std::string& onnx_path);

  // Raw network output (1 x 1 x h x w logits, CV_32F h x w) for an input already at input_size(),
  // CV_32F in [0, 1]. For the PyTorch comparison test.
  cv::Mat logits(const cv::Mat& input_01);
  // The 8-bit map at the model's input size.
  cv::Mat predict(const cv::Mat& left_gray, double timestamp,
                  const std::string& left_path) override;
  cv::Mat predict(const cv::Mat& left_gray) { return predict(left_gray, 0.0, ""); }

  cv::Size input_size() const { return input_size_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  cv::Size input_size_;
  cv::dnn::Net net_;
};

}  // namespace sbaslam::saliency
