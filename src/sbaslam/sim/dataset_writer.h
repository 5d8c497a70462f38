#pragma once
// Writes a rendered scene in the layout of the real dataset it imitates, so the dataset readers
// read it unchanged:
//   KITTI odometry (city scenes, straight):
//     DIR/sequences/00/{image_0,image_1,depth,semantic}/NNNNNN.png, calib.txt, times.txt
//     DIR/poses/00.txt (left camera, first pose at the origin, 3x4 row-major)
//   EuRoC ASL (room):
//     DIR/mav0/{cam0,cam1,depth0,semantic0}/{data.csv,data/<ns>.png}, cam*/sensor.yaml,
//     DIR/mav0/state_groundtruth_estimate0/data.csv (body poses at 200 Hz), DIR/mav0/body.yaml
//   both: DIR/scene.json (scene, seed and every parameter), DIR/settings.yaml (ORB-SLAM3 format).
// Depth is a 16-bit PNG, metres = value / 256 (z in the left camera), 0 = no depth. Semantic
// labels are 8-bit PNGs of Cityscapes label ids.

#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "sbaslam/core/settings.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam::sim {

constexpr double kDepthPngScale = 256.0;

// Metres (CV_32F) to the 16-bit PNG encoding; depths that do not fit become 0.
cv::Mat encode_depth(const cv::Mat& depth_m);

struct WriteOptions {
  int frames = 0;   // 0: the scene's default
  int threads = 2;  // frames rendered in parallel; the output does not depend on it
  // KITTI layout: also velodyne/NNNNNN.bin scans (sim/velodyne_sampler.h), ~0.4 MB a frame.
  bool velodyne = false;
  // Called from the calling thread with (frames written, total) while writing.
  std::function<void(int, int)> progress;
  // Asked before each frame is started; once it returns true, the frames being rendered are
  // finished, no other is started, and the dataset is left incomplete (no ground truth).
  std::function<bool()> stop_requested;
};

// Renders and writes the frames; throws sbaslam::Error when DIR cannot be written or the frame
// count is invalid. Returns the number of frames written: fewer than asked only when
// `stop_requested` stopped it.
int write_dataset(const Scene& scene, const std::string& out_dir, const WriteOptions& options);

// The ORB-SLAM3 settings `sba-slam run` uses for the scene.
Settings scene_settings(const Scene& scene);

// Nanosecond timestamp of a frame in the EuRoC layout.
long long euroc_timestamp_ns(const Scene& scene, int frame);

}  // namespace sbaslam::sim
