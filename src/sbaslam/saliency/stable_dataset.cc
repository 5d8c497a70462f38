#include "sbaslam/saliency/stable_dataset.h"

#include <filesystem>
#include <map>

#include "sbaslam/core/error.h"
#include "sbaslam/io/image_io.h"

namespace sbaslam::saliency {
namespace fs = std::filesystem;

std::vector<StableImage> stable_images(const std::vector<StableFeature>& rows,
                                       const std::string& images_dir, const std::string& csv_path) {
  if (!fs::is_directory(images_dir)) fail("{}: not a folder", images_dir);
  std::vector<StableImage> images;
  std::map<std::string, std::size_t> index_of;
  for (const StableFeature& row : rows) {
    auto [it, inserted] = index_of.emplace(row.image, images.size());
    if (inserted) {
      const fs::path path = fs::path(images_dir) / row.image;
      if (!fs::is_regular_file(path))
        fail("{}: image listed in {} not found", path.string(), csv_path);
      images.push_back({path.string(), fs::path(row.image).stem().string() + ".png", {}});
    }
    images[it->second].points.emplace_back(row.x, row.y);
  }
  return images;
}

int write_stable_dataset(const std::string& images_dir, const std::string& csv_path,
                         const std::string& out_dir, const SalientDatasetOptions& options) {
  const std::vector<StableImage> images =
      stable_images(read_stable_features_csv(csv_path), images_dir, csv_path);
  if (images.empty()) fail("{}: no stable features (the run kept no stable map point)", csv_path);
  SalientDatasetWriter writer(out_dir);
  const std::string label_source = fs::absolute(csv_path).string();
  for (const StableImage& image : images) {
    const cv::Mat gray = io::read_gray_image(image.image_path);
    writer.add(image.image_path, label_source, image.output_name,
               make_sample_from_points(gray, image.points, options));
  }
  return writer.count();
}

}  // namespace sbaslam::saliency
