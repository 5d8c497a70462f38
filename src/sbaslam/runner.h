#pragma once
// Runs a dataset through the system and writes what `sba-slam run` promises: trajectory.tum
// (every tracked frame), trajectory.kitti (KITTI datasets), keyframes.tum, timing.json, run.json,
// and on request stable_features.csv (saliency/stable_features.h).
// Orchestration only: reading, wiring, writing.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/core/trajectory.h"
#include "sbaslam/saliency/stable_features.h"

namespace sbaslam {

struct RunConfig {
  std::string settings_path;
  std::string dataset_kind;  // kitti | euroc | tum
  std::string dataset_path;
  std::string sensor = "stereo";  // stereo | mono
  std::string out_dir;
  std::optional<std::uint64_t> seed;    // overrides System.seed
  bool deterministic = false;           // or System.deterministic in the settings
  std::optional<std::string> saliency;  // overrides Saliency.source: none | model | DIR
  std::optional<bool> loop_closing;     // overrides the settings' loopClosing
  std::size_t max_frames = 0;           // 0: all
  // Feed frames at the dataset's own rate (by timestamp), as ORB-SLAM3's examples do, instead of
  // as fast as possible. Tracking then meets local mapping as on a live camera.
  bool realtime = false;
  bool progress = true;  // a progress line on stderr when it is a terminal
  // Also write stable_features.csv (self-supervised saliency labels) after the normal outputs.
  bool export_stable_features = false;
  saliency::StabilityGate stable_gate;
  // Map files (map/map_file.h); override the settings' System.LoadAtlasFromFile and
  // System.SaveAtlasToFile. localization_only needs a map to load (SystemOptions).
  std::optional<std::string> load_map;
  std::optional<std::string> save_map;
  bool localization_only = false;
};

struct RunResult {
  std::size_t frames = 0;
  std::size_t frames_tracked = 0;
  std::size_t keyframes = 0;
  std::size_t map_points = 0;
  int maps = 0;  // started in this run (a loaded map's are not counted)
  std::size_t loaded_keyframes = 0;
  std::size_t saved_keyframes = 0;
  std::string saved_map;  // the map file written, if any
  double map_save_ms = 0.0;
  std::size_t loops_closed = 0;
  std::string status;  // "ok", or why no map was made
  double tracking_median_ms = 0.0;
  double local_ba_median_ms = 0.0;
  Trajectory trajectory;  // as written to trajectory.tum
  // Monocular maps never merged into the biggest map: frames written to their own file, by map id.
  std::map<std::size_t, std::size_t> own_world_frames;
  int stop_signal = 0;  // SIGINT or SIGTERM when a signal ended the run early (stop_signal.h)
  // With export_stable_features: rows of stable_features.csv and the points they come from.
  std::size_t stable_feature_rows = 0;
  std::size_t stable_points = 0;
};

// Throws sbaslam::Error for bad input (settings, dataset, output folder). Tracking loss is not an
// error: the trajectory is written whatever happens.
RunResult run_sequence(const RunConfig& config);

}  // namespace sbaslam
