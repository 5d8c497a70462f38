#pragma once
// KITTI velodyne scans as distributed (sequences/XX/velodyne/NNNNNN.bin): per point four
// little-endian float32 values x, y, z, reflectance, in the scanner's frame (x forward, y left,
// z up, metres).

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sbaslam::io {

struct VelodynePoint {
  Eigen::Vector3f xyz = Eigen::Vector3f::Zero();
  float reflectance = 0.0f;
};

// Throws sbaslam::Error naming the file for a missing or unreadable file, a size that is not a
// whole number of points, or a non-finite coordinate. An empty file is an empty scan.
std::vector<VelodynePoint> read_velodyne_scan(const std::string& path);

void write_velodyne_scan(const std::string& path, const std::vector<VelodynePoint>& scan);

}  // namespace sbaslam::io
