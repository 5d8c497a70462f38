// sba-slam demo: the quick start. Renders a short synthetic city drive, runs stereo SLAM on it and
// evaluates the result against the exact ground truth.

#include <fmt/format.h>

#include <iostream>

#include "commands.h"
#include "sbaslam/core/stop_signal.h"
#include "sbaslam/demo.h"

namespace sbaslam::cli {

void add_demo_command(CLI::App& app) {
  auto config = std::make_shared<DemoConfig>();
  CLI::App* demo = app.add_subcommand(
      "demo", "Render a synthetic city drive, run stereo SLAM on it and evaluate it");
  demo->add_option("--frames", config->frames, "Frames to render (10 Hz)")->capture_default_str();
  demo->add_option("--seed", config->seed, "Seed of the scene and of the run")
      ->capture_default_str();
  demo->add_option("--work-dir", config->work_dir, "Keep the sequence and the run here");
  demo->callback([config] {
    const DemoResult r = run_demo(*config);
    if (r.stop_signal) {
      // Exit as shells expect of that signal, as `sba-slam run` does.
      std::cerr << fmt::format("sba-slam demo: stopped by {}; nothing evaluated\n",
                               stop_signal_name(r.stop_signal));
      throw CLI::RuntimeError(128 + r.stop_signal);
    }
    std::cout << fmt::format(
        "\nsba-slam demo: synthetic city-loop, stereo, {} frames, {:.0f} m driven\n"
        "  tracked frames       {}/{}  ({} keyframes)\n"
        "  ATE (SE3-aligned)    {:.3f} m RMSE\n"
        "  RPE (1 frame)        {:.3f} m RMSE\n",
        r.frames, r.path_length_m, r.frames_tracked, r.frames, r.keyframes, r.ate_rmse_m,
        r.rpe_rmse_m);
    if (r.rpe_100m_percent > 0.0)
      std::cout << fmt::format("  RPE (100 m)          {:.2f} % RMSE\n", r.rpe_100m_percent);
    std::cout << fmt::format("  tracking time        {:.1f} ms/frame (median)\n",
                             r.tracking_median_ms);
    if (!config->work_dir.empty())
      std::cout << fmt::format("  output in            {}\n", config->work_dir);
  });
}

}  // namespace sbaslam::cli
