#include "sbaslam/io/dataset.h"

#include <filesystem>

#include "sbaslam/core/error.h"
#include "sbaslam/io/euroc_reader.h"
#include "sbaslam/io/kitti_reader.h"
#include "sbaslam/io/tum_reader.h"

namespace sbaslam::io {

DatasetReader::~DatasetReader() = default;

std::unique_ptr<DatasetReader> make_dataset_reader(const std::string& kind, const std::string& path,
                                                   const DatasetOptions& options) {
  if (kind != "kitti" && kind != "euroc" && kind != "tum")
    fail("unknown dataset kind '{}' (expected kitti, euroc or tum)", kind);
  if (!std::filesystem::is_directory(path)) fail("{}: dataset folder not found", path);
  if (kind == "kitti") return std::make_unique<KittiReader>(path, options);
  if (kind == "euroc") return std::make_unique<EurocReader>(path, options);
  return std::make_unique<TumReader>(path, options);
}

void check_increasing_stamps(const std::vector<double>& stamps, const std::string& path) {
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] == stamps[i - 1])
      fail("{}: duplicate timestamp {:.9f} (entries {} and {})", path, stamps[i], i, i + 1);
    if (stamps[i] < stamps[i - 1])
      fail("{}: timestamps are not sorted: entry {} ({:.9f}) comes before entry {} ({:.9f})", path,
           i + 1, stamps[i], i, stamps[i - 1]);
  }
}

}  // namespace sbaslam::io
