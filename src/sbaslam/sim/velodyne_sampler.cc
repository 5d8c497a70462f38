#include "sbaslam/sim/velodyne_sampler.h"

#include <cmath>

namespace sbaslam::sim {

SE3 camera_from_velodyne() {
  Mat3 R;  // velodyne x forward -> camera z, y left -> -x, z up -> -y
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  return SE3(SO3::from_matrix(R), Vec3(0.0, -0.08, -0.27));
}

std::vector<io::VelodynePoint> sample_velodyne_scan(const cv::Mat& depth,
                                                    const ViewCamera& camera) {
  constexpr int kBeams = 64;
  constexpr double kTopDeg = 2.0, kBottomDeg = -24.8;
  const SE3 velodyne_from_camera = camera_from_velodyne().inverse();
  std::vector<io::VelodynePoint> scan;
  for (int beam = 0; beam < kBeams; ++beam) {
    const double elevation =
        (kTopDeg + (kBottomDeg - kTopDeg) * beam / (kBeams - 1)) * M_PI / 180.0;
    const int row = static_cast<int>(std::lround(camera.cy - camera.fy * std::tan(elevation)));
    if (row < 0 || row >= depth.rows) continue;
    const float* d = depth.ptr<float>(row);
    for (int col = 0; col < depth.cols; col += 2) {
      if (!(d[col] > 0.0f)) continue;
      const Vec3 in_camera(d[col] * (col - camera.cx) / camera.fx,
                           d[col] * (row - camera.cy) / camera.fy, d[col]);
      io::VelodynePoint p;
      p.xyz = (velodyne_from_camera * in_camera).cast<float>();
      p.reflectance = 0.5f;
      scan.push_back(p);
    }
  }
  return scan;
}

}  // namespace sbaslam::sim
