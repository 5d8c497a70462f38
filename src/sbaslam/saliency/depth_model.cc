#include "sbaslam/saliency/depth_model.h"

#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam::saliency {

DepthModel::DepthModel(const DepthModelSettings& settings) : settings_(settings) {
  if (!std::filesystem::is_regular_file(settings.path))
    fail("{}: depth model file does not exist", settings.path);
  try {
    net_ = cv::dnn::readNetFromONNX(settings.path);
  } catch (const cv::Exception& e) {
    fail("{}: not a readable ONNX model: {}", settings.path, e.err);
  }
  if (net_.empty()) fail("{}: not a readable ONNX model", settings.path);
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

cv::Mat DepthModel::predict(const cv::Mat& gray) {
  if (gray.empty() || gray.type() != CV_8UC1)
    fail("{}: depth model input must be an 8-bit grey image", settings_.path);
  cv::Mat resized, input;
  cv::resize(gray, resized, cv::Size(settings_.width, settings_.height), 0, 0, cv::INTER_AREA);
  if (settings_.channels == 3) cv::cvtColor(resized, resized, cv::COLOR_GRAY2RGB);
  resized.convertTo(input, CV_32F, 1.0 / 255.0);
  cv::Mat out;
  try {
    net_.setInput(cv::dnn::blobFromImage(input));
    out = net_.forward();
  } catch (const cv::Exception& e) {
    fail("{}: inference failed: {}", settings_.path, e.err);
  }
  if (out.dims != 4 || out.size[0] != 1 || out.size[1] != 1)
    fail("{}: depth model output must be 1x1xHxW", settings_.path);
  const cv::Mat raw(out.size[2], out.size[3], CV_32F, out.ptr<float>());
  cv::Mat depth(raw.size(), CV_32F, cv::Scalar(0));
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      const float v = raw.at<float>(y, x);
      const float d = settings_.inverse ? (v > 0.0f ? 1.0f / v : 0.0f) : v;
      if (std::isfinite(d) && d > 0.0f) depth.at<float>(y, x) = d;
    }
  return depth;
}

}  // namespace sbaslam::saliency
