// Accuracy of the stereo matches against a render's exact depth, per pyramid level: the signed
// disparity error (estimate minus truth, pixels) of every matched keypoint whose 3x3 neighbourhood
// lies on one surface (depths within 2 %), on up to 60 frames spread over the sequence.
//
//   stereo_depth_accuracy kitti /tmp/city_loop/sequences/00 /tmp/city_loop/settings.yaml
//   stereo_depth_accuracy euroc /tmp/room /tmp/room/settings.yaml
//
// A positive error means the match puts the point too near. Prints one row per level.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sbaslam/core/error.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/io/dataset.h"

namespace {

using namespace sbaslam;

// The render's depth image of a frame: KITTI layout depth/NNNNNN.png beside image_0/, EuRoC
// layout mav0/depth0/data/<ns>.png beside cam0/.
std::string depth_path_of(const std::string& left_path) {
  std::string path = left_path;
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"/image_0/", "/depth/"}, {"/cam0/", "/depth0/"}}) {
    const std::size_t at = path.rfind(from);
    if (at != std::string::npos) return path.replace(at, from.size(), to);
  }
  fail("{}: not in a render's image_0/ or cam0/ folder", left_path);
}

// Truth in metres at a keypoint, or 0 when the 3x3 neighbourhood spans more than one surface.
double surface_depth(const cv::Mat& depth_png, float x, float y) {
  const int cx = static_cast<int>(std::lround(x)), cy = static_cast<int>(std::lround(y));
  double lo = 1e9, hi = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int px = std::clamp(cx + dx, 0, depth_png.cols - 1);
      const int py = std::clamp(cy + dy, 0, depth_png.rows - 1);
      const double z = depth_png.at<std::uint16_t>(py, px) / 256.0;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  return lo > 0.0 && hi - lo <= 0.02 * lo ? depth_png.at<std::uint16_t>(cy, cx) / 256.0 : 0.0;
}

void print_level(int level, std::vector<double> errors) {
  std::sort(errors.begin(), errors.end());
  const auto share = [&](auto predicate) {
    return 100.0 * static_cast<double>(std::count_if(errors.begin(), errors.end(), predicate)) /
           static_cast<double>(errors.size());
  };
  const auto at = [&](double q) {
    return errors[static_cast<std::size_t>(q * static_cast<double>(errors.size() - 1))];
  };
  std::printf("%5d %7zu %+8.3f %+8.3f %+8.3f %7.2f %7.2f %7.2f\n", level, errors.size(), at(0.1),
              at(0.5), at(0.9), share([](double e) { return e > 1.0; }),
              share([](double e) { return e < -1.0; }), share([](double e) { return e > 3.0; }));
}

void run(const std::string& kind, const std::string& path, const std::string& settings_path) {
  const Settings settings = load_settings(settings_path);
  io::DatasetOptions options;
  options.load_depth = false;
  const auto reader = io::make_dataset_reader(kind, path, options);
  const auto calibration = reader->calibration();
  if (!reader->has_right() || !calibration || !calibration->stereo)
    fail("{}: needs a rectified stereo pair", path);
  if (calibration->T_cam0_image.so3().angle() > 1e-9)
    fail("{}: the reader rotates the images, so the render's depth is not registered to them",
         path);
  feature::StereoExtractor extractor(settings.orb, *calibration->stereo);
  const double bf = calibration->stereo->bf;
  std::map<int, std::vector<double>> errors;
  const std::size_t step = std::max<std::size_t>(1, reader->size() / 60);
  for (std::size_t i = 0; i < reader->size(); i += step) {
    const io::FrameData frame = reader->load(i);
    const std::string depth_path = depth_path_of(frame.left_path);
    const cv::Mat truth = cv::imread(depth_path, cv::IMREAD_UNCHANGED);
    if (truth.type() != CV_16U || truth.size() != frame.left.size())
      fail("{}: not a 16-bit depth image of the frame's size", depth_path);
    const feature::StereoFeatures features = extractor.extract(frame.left, frame.right);
    for (std::size_t k = 0; k < features.left.keypoints.size(); ++k) {
      if (features.matches.depth[k] <= 0.0f) continue;
      const feature::OrbKeypoint& kp = features.left.keypoints[k];
      const double z = surface_depth(truth, kp.x, kp.y);
      if (z > 0.0) errors[kp.octave].push_back(bf / features.matches.depth[k] - bf / z);
    }
  }
  std::printf("disparity error (px) of matched keypoints, %s\n", path.c_str());
  std::printf("level       n      p10   median      p90  >+1px%%  <-1px%%  >+3px%%\n");
  for (const auto& [level, e] : errors) print_level(level, e);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s kitti|euroc DATASET SETTINGS\n", argv[0]);
    return 2;
  }
  try {
    run(argv[1], argv[2], argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stereo_depth_accuracy: %s\n", e.what());
    return 1;
  }
  return 0;
}
