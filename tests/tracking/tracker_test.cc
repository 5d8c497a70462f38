// Tracker::predicted_point_depths, the depth a monocular frame gives Algorithm 1 (depth-corrected
// saliency): the map points of the last frame, predicted into the next one by the motion model,
// must sit where the next frame's true depth agrees with them up to the map's unknown scale.

#include "sbaslam/tracking/tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "helper/temp_dir.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"
#include "sbaslam/system.h"

namespace sbaslam::tracking {
namespace {

struct DepthPair {
  double predicted = 0.0;  // map units
  double truth = 0.0;      // metres, rendered
};

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

TEST(Tracker, PredictedMonocularPointDepthsMatchTheNextFramesTrueDepthUpToScale) {
  test::TempDir dir;
  sim::SceneOptions scene_options;
  scene_options.name = "city-loop";
  const sim::Scene scene = sim::make_scene(scene_options);
  sim::WriteOptions write;
  write.frames = 1;  // only for the settings file the scene's camera gives
  sim::write_dataset(scene, dir.file("data"), write);
  const Settings settings = load_settings(dir.file("data/settings.yaml"));
  SystemOptions options;
  options.stereo = false;
  options.deterministic = true;
  System system(settings, settings.camera, settings.stereo, options);

  std::vector<DepthPair> pairs;
  int frames_with_prediction = 0;
  for (int k = 0; k < 25; ++k) {
    const std::vector<saliency::DepthSample> predicted = system.tracker().predicted_point_depths();
    const sim::StereoFrame frame = sim::render_frame(scene, k);
    if (!predicted.empty()) ++frames_with_prediction;
    for (const saliency::DepthSample& s : predicted) {
      const float truth = frame.depth.at<float>(static_cast<int>(s.v), static_cast<int>(s.u));
      if (truth > 0.0f) pairs.push_back({s.depth, truth});
    }
    system.process(k * 0.1, frame.left, cv::Mat());
  }
  system.shutdown();
  ASSERT_GE(frames_with_prediction, 15) << "monocular map not initialised in time";
  ASSERT_GE(pairs.size(), 1000u);
  std::vector<double> ratio;
  for (const DepthPair& p : pairs) ratio.push_back(p.truth / p.predicted);
  const double scale = quantile(ratio, 0.5);
  std::vector<double> relative_error;
  for (double r : ratio) relative_error.push_back(std::abs(r / scale - 1.0));
  const double median_error = quantile(relative_error, 0.5);
  const double p80_error = quantile(relative_error, 0.8);
  std::printf(
      "%zu samples over %d frames: scale %.3f m per map unit, relative depth error "
      "median %.4f, 80th percentile %.4f\n",
      pairs.size(), frames_with_prediction, scale, median_error, p80_error);
  EXPECT_LT(median_error, 0.05);
  EXPECT_LT(p80_error, 0.15);
}

}  // namespace
}  // namespace sbaslam::tracking
