#pragma once
// The quick-start demo: render a short synthetic city-loop stereo sequence, run SLAM on it,
// evaluate the estimate against the exact ground truth with the project's evaluator. It needs no
// data besides the project's own.

#include <cstdint>
#include <string>

namespace sbaslam {

struct DemoConfig {
  int frames = 200;
  std::uint64_t seed = 1;
  std::string work_dir;  // empty: a fresh temporary folder, removed afterwards
  bool keep = false;     // keep the rendered sequence and the run's output
};

struct DemoResult {
  std::string work_dir;
  std::size_t frames_rendered = 0;
  std::size_t frames = 0, frames_tracked = 0, keyframes = 0;
  double path_length_m = 0.0;
  double ate_rmse_m = 0.0;        // APE, SE3-aligned, translation
  double rpe_rmse_m = 0.0;        // RPE over 1 frame, translation
  double rpe_100m_percent = 0.0;  // RPE over 100 m (evo pairs), translation, % of 100 m
  double tracking_median_ms = 0.0;
  // SIGINT or SIGTERM when a signal stopped the rendering or the SLAM run (nothing is evaluated
  // then, and the temporary folder is removed as always), or 0.
  int stop_signal = 0;
};

DemoResult run_demo(const DemoConfig& config);

}  // namespace sbaslam
