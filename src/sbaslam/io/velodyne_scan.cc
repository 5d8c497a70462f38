#include "sbaslam/io/velodyne_scan.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::io {

std::vector<VelodynePoint> read_velodyne_scan(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot open the velodyne scan", path);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  if (in.bad()) fail("{}: cannot read the velodyne scan", path);
  constexpr std::size_t kPointBytes = 4 * sizeof(float);
  if (bytes.size() % kPointBytes != 0)
    fail("{}: {} bytes is not a whole number of 16-byte points (x, y, z, reflectance)", path,
         bytes.size());
  std::vector<VelodynePoint> scan(bytes.size() / kPointBytes);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    float v[4];
    std::memcpy(v, bytes.data() + i * kPointBytes, kPointBytes);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      fail("{}: point {} has a non-finite coordinate", path, i);
    scan[i].xyz = Eigen::Vector3f(v[0], v[1], v[2]);
    scan[i].reflectance = v[3];
  }
  return scan;
}

void write_velodyne_scan(const std::string& path, const std::vector<VelodynePoint>& scan) {
  std::ofstream out = open_output_file(path);
  for (const VelodynePoint& p : scan) {
    const float v[4] = {p.xyz.x(), p.xyz.y(), p.xyz.z(), p.reflectance};
    out.write(reinterpret_cast<const char*>(v), sizeof(v));
  }
  close_output_file(out, path);
}

}  // namespace sbaslam::io
