#include "sbaslam/saliency/saliency_source.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/saliency/saliency_model.h"

namespace sbaslam::saliency {
namespace fs = std::filesystem;

SaliencySource::~SaliencySource() = default;

PrecomputedSaliency::PrecomputedSaliency(std::string folder) : folder_(std::move(folder)) {
  if (!fs::is_directory(folder_)) fail("{}: saliency folder does not exist", folder_);
}

cv::Mat PrecomputedSaliency::predict(const cv::Mat& /*left_gray*/, double /*timestamp*/,
                                     const std::string& left_path) {
  const fs::path name = fs::path(left_path).filename();
  fs::path map_path = fs::path(folder_) / name;
  if (!fs::exists(map_path)) map_path = fs::path(folder_) / name.stem().concat(".png");
  if (!fs::exists(map_path))
    fail("{}: no saliency map for image {}", (fs::path(folder_) / name).string(), left_path);
  cv::Mat map = cv::imread(map_path.string(), cv::IMREAD_GRAYSCALE);
  if (map.empty()) fail("{}: not a readable image", map_path.string());
  return map;
}

std::string saliency_model_file(const std::string& spec, const SaliencySettings& settings) {
  if (spec != "model") return {};
  return settings.model_path.empty() ? shipped_model_path() : settings.model_path;
}

std::unique_ptr<SaliencySource> make_saliency_source(const std::string& spec,
                                                     const SaliencySettings& settings) {
  if (spec == "none") return std::make_unique<UniformSaliency>();
  if (spec == "model") return std::make_unique<SaliencyModel>(saliency_model_file(spec, settings));
  if (fs::is_directory(spec)) return std::make_unique<PrecomputedSaliency>(spec);
  fail("{}: saliency source must be 'none', 'model' or a folder of saliency maps", spec);
}

}  // namespace sbaslam::saliency
