#include "sbaslam/saliency/velodyne_depth.h"

#include "sbaslam/core/error.h"
#include "sbaslam/io/kitti_reader.h"

namespace sbaslam::saliency {
namespace fs = std::filesystem;

std::vector<DepthSample> project_scan(const std::vector<io::VelodynePoint>& scan,
                                      const SE3& T_camera_velodyne, const PinholeIntrinsics& k,
                                      const cv::Size& image_size, double min_depth) {
  std::vector<DepthSample> samples;
  for (const io::VelodynePoint& p : scan) {
    const Vec3 c = T_camera_velodyne * p.xyz.cast<double>();
    if (c.z() < min_depth) continue;
    const double u = k.fx * c.x() / c.z() + k.cx, v = k.fy * c.y() / c.z() + k.cy;
    if (u < 0.0 || v < 0.0 || u >= image_size.width || v >= image_size.height) continue;
    samples.push_back({static_cast<float>(u), static_cast<float>(v), static_cast<float>(c.z())});
  }
  return samples;
}

VelodyneDepth::VelodyneDepth(const PinholeIntrinsics& k, const cv::Size& image_size)
    : k_(k), image_size_(image_size) {}

const SE3& VelodyneDepth::camera_from_velodyne(const fs::path& sequence_dir) {
  const auto known = calibration_.find(sequence_dir);
  if (known != calibration_.end()) return known->second;
  const std::string calib = (sequence_dir / "calib.txt").string();
  const auto rows = io::read_kitti_calibration_rows(calib);
  const auto tr = rows.find("Tr");
  if (tr == rows.end()) fail("{}: no Tr row (velodyne to camera), needed by Saliency.depth", calib);
  return calibration_.emplace(sequence_dir, SE3::from_matrix(tr->second)).first->second;
}

std::vector<DepthSample> VelodyneDepth::samples_for(const std::string& left_image_path) {
  const fs::path image(left_image_path);
  const fs::path sequence_dir = image.parent_path().parent_path();
  const fs::path scan_path = sequence_dir / "velodyne" / (image.stem().string() + ".bin");
  if (!fs::is_regular_file(scan_path))
    fail("{}: velodyne scan not found (Saliency.depth is \"velodyne\")", scan_path.string());
  return project_scan(io::read_velodyne_scan(scan_path.string()),
                      camera_from_velodyne(sequence_dir), k_, image_size_);
}

}  // namespace sbaslam::saliency
