#include "sbaslam/demo.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <utility>

#include "sbaslam/core/error.h"
#include "sbaslam/core/stop_signal.h"
#include "sbaslam/eval/evaluator.h"
#include "sbaslam/runner.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam {
namespace {

std::string fresh_temp_dir() {
  // Only the folder name depends on the clock; nothing computed does.
  const auto nonce = static_cast<unsigned>(
      std::filesystem::file_time_type::clock::now().time_since_epoch().count());
  for (int attempt = 0; attempt < 100; ++attempt) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("sba-slam-demo-" + std::to_string(nonce + static_cast<unsigned>(attempt)));
    if (std::filesystem::create_directory(dir)) return dir.string();
  }
  fail("{}: cannot create a temporary folder", std::filesystem::temp_directory_path().string());
}

// Removes the demo's temporary folder when the demo ends, however it ends (an error, a signal).
class TemporaryFolder {
 public:
  TemporaryFolder(std::string path, bool remove) : path_(std::move(path)), remove_(remove) {}
  ~TemporaryFolder() {
    std::error_code ec;  // nothing to report from a destructor: the folder is a temporary one
    if (remove_) std::filesystem::remove_all(path_, ec);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;

 private:
  std::string path_;
  bool remove_;
};

eval::EvalResult evaluate(const std::string& gt, const std::string& est, eval::Metric metric,
                          double delta, eval::DeltaUnit unit) {
  eval::EvalSettings s;
  s.metric = metric;
  s.format = io::TrajectoryFormat::kKitti;
  s.reference_path = gt;
  s.estimate_path = est;
  s.align = metric == eval::Metric::kApe ? eval::AlignmentMode::kSe3 : eval::AlignmentMode::kNone;
  s.rpe.delta = delta;
  s.rpe.unit = unit;
  return eval::evaluate(s);
}

}  // namespace

DemoResult run_demo(const DemoConfig& config) {
  if (config.frames < 10)
    fail("--frames: the demo needs at least 10 frames, got {}", config.frames);
  DemoResult result;
  result.work_dir = config.work_dir.empty() ? fresh_temp_dir() : config.work_dir;
  const TemporaryFolder work_dir(result.work_dir, config.work_dir.empty() && !config.keep);
  const std::string data = result.work_dir + "/city-loop";
  const std::string out = result.work_dir + "/run";
  // One guard from rendering to the end: the SLAM run's own guard shares its flag.
  const StopSignalGuard stop;

  sim::SceneOptions scene_options;
  scene_options.name = "city-loop";
  scene_options.seed = config.seed;
  const sim::Scene scene = sim::make_scene(scene_options);
  sim::WriteOptions write;
  write.frames = config.frames;
  write.stop_requested = [&stop] { return stop.received() != 0; };
  spdlog::info("rendering {} frames of city-loop into {}", config.frames, data);
  result.frames_rendered = static_cast<std::size_t>(sim::write_dataset(scene, data, write));
  if (stop.received()) {
    result.stop_signal = stop.received();
    return result;
  }

  RunConfig run;
  run.settings_path = data + "/settings.yaml";
  run.dataset_kind = "kitti";
  run.dataset_path = data + "/sequences/00";
  run.sensor = "stereo";
  run.out_dir = out;
  run.seed = config.seed;
  const RunResult r = run_sequence(run);
  if (stop.received()) {
    // A stopped run's trajectory is partial: its figures would not be the demo's.
    result.stop_signal = stop.received();
    return result;
  }

  const std::string gt = data + "/poses/00.txt";
  const std::string est = out + "/trajectory.kitti";
  result.frames = r.frames;
  result.frames_tracked = r.frames_tracked;
  result.keyframes = r.keyframes;
  result.tracking_median_ms = r.tracking_median_ms;
  result.ate_rmse_m = evaluate(gt, est, eval::Metric::kApe, 1, eval::DeltaUnit::kFrames).stats.rmse;
  result.rpe_rmse_m = evaluate(gt, est, eval::Metric::kRpe, 1, eval::DeltaUnit::kFrames).stats.rmse;
  result.path_length_m = r.trajectory.path_length();
  if (result.path_length_m > 120.0)
    result.rpe_100m_percent =
        100.0 * evaluate(gt, est, eval::Metric::kRpe, 100, eval::DeltaUnit::kMeters).stats.rmse /
        100.0;
  return result;
}

}  // namespace sbaslam
