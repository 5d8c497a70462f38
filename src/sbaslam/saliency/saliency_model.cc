#include "sbaslam/saliency/saliency_model.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/shipped_file.h"

namespace sbaslam::saliency {
namespace fs = std::filesystem;

namespace {

constexpr const char* kModelFile = "saliency_model.onnx";

cv::Size read_input_size(const std::string& onnx_path) {
  const std::string card = fs::path(onnx_path).replace_extension(".json").string();
  std::ifstream in(card);
  if (!in) fail("{}: model card missing (it gives the model's input size)", card);
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    const auto& size = j.at("input_size");
    const cv::Size s(size.at(0).get<int>(), size.at(1).get<int>());
    if (s.width <= 0 || s.height <= 0) fail("{}: input_size must be positive", card);
    return s;
  } catch (const nlohmann::json::exception& e) {
    fail("{}: invalid model card: {}", card, e.what());
  }
}

}  // namespace

std::string shipped_model_path() {
  return shipped_file_path(kModelFile, "saliency model");
}

SaliencyModel::SaliencyModel(const std::string& onnx_path) : path_(onnx_path) {
  if (!fs::is_regular_file(onnx_path)) fail("{}: saliency model file does not exist", onnx_path);
  input_size_ = read_input_size(onnx_path);
  try {
    net_ = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    fail("{}: not a readable ONNX model: {}", onnx_path, e.err);
  }
  if (net_.empty()) fail("{}: not a readable ONNX model", onnx_path);
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

cv::Mat SaliencyModel::logits(const cv::Mat& input_01) {
  CV_Assert(input_01.type() == CV_32FC1 && input_01.size() == input_size_);
  net_.setInput(cv::dnn::blobFromImage(input_01));
  cv::Mat out;
  try {
    out = net_.forward();
  } catch (const cv::Exception& e) {
    fail("{}: inference failed: {}", path_, e.err);
  }
  if (out.dims != 4 || out.size[2] != input_size_.height || out.size[3] != input_size_.width)
    fail("{}: output is not a 1x1x{}x{} map", path_, input_size_.height, input_size_.width);
  return cv::Mat(input_size_.height, input_size_.width, CV_32F, out.ptr<float>()).clone();
}

cv::Mat SaliencyModel::predict(const cv::Mat& left_gray, double /*timestamp*/,
                               const std::string& /*left_path*/) {
  if (left_gray.empty() || left_gray.type() != CV_8UC1)
    fail("{}: saliency input must be an 8-bit grayscale image", path_);
  cv::Mat resized, input;
  cv::resize(left_gray, resized, input_size_, 0, 0, cv::INTER_AREA);
  resized.convertTo(input, CV_32F, 1.0 / 255.0);
  cv::Mat z = logits(input);
  double max_z = 0.0;
  cv::minMaxLoc(z, nullptr, &max_z);
  cv::Mat density;
  cv::exp(z - max_z, density);
  cv::Mat map;
  density.convertTo(map, CV_8U, 255.0);
  return map;
}

}  // namespace sbaslam::saliency
