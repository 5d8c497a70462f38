#include "sbaslam/runner.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/core/stop_signal.h"
#include "sbaslam/core/timing.h"
#include "sbaslam/io/dataset.h"
#include "sbaslam/io/dataset_geometry.h"
#include "sbaslam/io/trajectory_io.h"
#include "sbaslam/saliency/saliency_source.h"
#include "sbaslam/stable_feature_export.h"
#include "sbaslam/system.h"

namespace sbaslam {
namespace {

// Plays a sequence at its recorded rate: frame i is due (t_i - t_0) after the first one. A frame
// already late is processed at once; the clock does not catch up by skipping frames.
class RealtimeClock {
 public:
  void wait_for(double timestamp) {
    if (!first_) {
      first_ = timestamp;
      start_ = std::chrono::steady_clock::now();
      return;
    }
    std::this_thread::sleep_until(start_ +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(timestamp - *first_)));
  }

 private:
  std::optional<double> first_;
  std::chrono::steady_clock::time_point start_;
};

void write_json(const std::string& path, const nlohmann::json& json) {
  write_output_file(path, json.dump(2) + "\n");
}

// KITTI files pair rows with the ground truth, so every input frame gets a row: frames before
// the first pose take the first pose, later untracked frames repeat the last one. run.json lists
// those frames.
Trajectory one_row_per_frame(const Trajectory& tracked, const std::vector<double>& all_stamps) {
  Trajectory rows;
  if (tracked.empty()) return rows;
  std::size_t next = 0;
  SE3 current = tracked.poses.front();
  for (double stamp : all_stamps) {
    if (next < tracked.size() && tracked.stamps[next] == stamp) current = tracked.poses[next++];
    rows.push_back(stamp, current);
  }
  return rows;
}

// Poses of cam0 (the dataset's left camera) rather than of the rectified image, with the world
// at cam0's first pose.
Trajectory to_cam0(const Trajectory& t, const SE3& T_cam0_image) {
  Trajectory out;
  const SE3 T_image_cam0 = T_cam0_image.inverse();
  for (std::size_t i = 0; i < t.size(); ++i)
    out.push_back(t.stamps[i], T_cam0_image * t.poses[i] * T_image_cam0);
  return out;
}

void show_progress(std::size_t i, std::size_t n, const System& system, double ms) {
  std::fprintf(stderr, "\r[%zu/%zu] keyframes %zu, %.1f ms/frame   ", i + 1, n,
               system.keyframe_count(), ms);
  if (i + 1 == n) std::fprintf(stderr, "\n");
}

// Writes OUT/stable_features.csv from the map, under the map lock (local mapping has stopped).
void export_stable_features(const System& system, const io::DatasetReader& reader,
                            const std::map<double, std::string>& image_of_stamp,
                            const RunConfig& config, RunResult& result) {
  StableFeatureSources sources;
  sources.image_of = [&image_of_stamp](double stamp) {
    const auto it = image_of_stamp.find(stamp);
    return it == image_of_stamp.end() ? fmt::format("{:.9f}", stamp) : it->second;
  };
  sources.file_pixel = [&reader](const Vec2& pixel) { return reader.file_pixel(pixel); };
  const std::string path = config.out_dir + "/stable_features.csv";
  system.read_map([&](const map::Map& map) {
    const std::vector<saliency::StableFeature> rows =
        saliency::select_stable_features(map_point_tracks(map, sources), config.stable_gate);
    saliency::write_stable_features_csv(path, rows);
    std::set<std::size_t> points;
    for (const saliency::StableFeature& r : rows) points.insert(r.point_id);
    result.stable_feature_rows = rows.size();
    result.stable_points = points.size();
  });
}

void check_run_config(const RunConfig& config) {
  if (config.sensor != "stereo" && config.sensor != "mono" && config.sensor != "rgbd")
    fail("--sensor: '{}' is not one of stereo, mono, rgbd", config.sensor);
  if (config.stable_gate.min_observations < 2)
    fail("--stable-min-observations: must be at least 2, got {}",
         config.stable_gate.min_observations);
  if (!(config.stable_gate.max_chi2 > 0.0))
    fail("--stable-max-chi2: must be positive, got {}", config.stable_gate.max_chi2);
}

// The map files of a run: the command line's, else the settings' (ORB-SLAM3 appends ".osa").
struct MapFiles {
  std::string load, save;
};

MapFiles map_files(const RunConfig& config, const Settings& settings) {
  const auto atlas = [](const std::string& name) { return name.empty() ? name : name + ".osa"; };
  MapFiles files{config.load_map.value_or(atlas(settings.system.load_atlas)),
                 config.save_map.value_or(atlas(settings.system.save_atlas))};
  if (config.localization_only && files.load.empty())
    fail(
        "--localization-only: needs a map to localise in (--load-map FILE, or the settings' "
        "System.LoadAtlasFromFile)");
  return files;
}

SystemOptions system_options(const RunConfig& config, const Settings& settings,
                             const MapFiles& files) {
  SystemOptions options;
  options.map_to_load = files.load;
  options.localization_only = config.localization_only;
  options.stereo = config.sensor == "stereo";
  options.rgbd = config.sensor == "rgbd";
  options.deterministic = config.deterministic || settings.system.deterministic;
  options.seed = config.seed.value_or(settings.system.seed);
  options.saliency = config.saliency.value_or(settings.saliency.source);
  options.wait_for_mapping = !config.realtime;
  return options;
}

// What the playback loop saw: how many frames it was to play, the stamps of those given to the
// system, and the frames skipped as unreadable.
struct Playback {
  std::size_t requested = 0;
  std::vector<double> stamps;
  std::map<double, std::string> image_of_stamp;  // file names, for stable_features.csv
  std::vector<std::size_t> unreadable;
};

Playback play(System& system, io::DatasetReader& reader, const RunConfig& config,
              const StopSignalGuard& stop) {
  Playback played;
  played.requested =
      config.max_frames > 0 ? std::min(config.max_frames, reader.size()) : reader.size();
  const std::size_t n = played.requested;
  const bool progress = config.progress && isatty(fileno(stderr));
  RealtimeClock clock;
  for (std::size_t i = 0; i < n && !stop.received(); ++i) {
    if (config.realtime) clock.wait_for(reader.timestamp(i));
    if (stop.received()) break;
    io::FrameData frame;
    try {
      frame = reader.load(i);
    } catch (const Error& e) {
      // One unreadable image in a long run is skipped, as users of the datasets expect.
      spdlog::warn("{} (frame skipped)", e.what());
      played.unreadable.push_back(i);
      continue;
    }
    played.stamps.push_back(frame.timestamp);
    if (config.export_stable_features)
      played.image_of_stamp[frame.timestamp] =
          std::filesystem::path(frame.left_path).filename().string();
    system.process(frame.timestamp, frame.left, frame.right, frame.left_path, frame.depth);
    if (progress) show_progress(i, n, system, system.last_tracking_ms());
  }
  if (progress && stop.received()) std::fprintf(stderr, "\n");
  return played;
}

void write_timing_json(const std::string& path, const SystemTimings& timings) {
  write_json(path, {{"tracking_ms", to_json(summarize(timings.tracking_ms))},
                    {"extraction_ms", to_json(summarize(timings.extraction_ms))},
                    {"saliency_ms", to_json(summarize(timings.saliency_ms))},
                    {"mapping_wait_ms", to_json(summarize(timings.mapping_wait_ms))},
                    {"frame_to_frame_ms", to_json(summarize(timings.tracking.frame_to_frame_ms))},
                    {"local_map_ms", to_json(summarize(timings.tracking.local_map_ms))},
                    {"keyframe_decision_ms", to_json(summarize(timings.tracking.keyframe_ms))},
                    {"map_lock_wait_ms", to_json(summarize(timings.tracking.map_lock_wait_ms))},
                    {"relocalization_ms", to_json(summarize(timings.tracking.relocalization_ms))},
                    {"local_ba_ms", to_json(summarize(timings.mapping.local_ba_ms))},
                    {"local_mapping_ms", to_json(summarize(timings.mapping.keyframe_ms))},
                    {"local_ba_interrupted", timings.mapping.local_ba_interrupted}});
}

nlohmann::json loop_closing_json(const System& system) {
  if (!system.loop_closing()) return {{"enabled", false}};
  const loop::LoopCloserReport report = system.loop_report();
  nlohmann::json loops = nlohmann::json::array();
  for (const loop::LoopClosure& c : report.loops)
    loops.push_back(
        {{"keyframe", c.keyframe_id},
         {"timestamp", c.timestamp},
         {"loop_keyframe", c.loop_keyframe_id},
         {"loop_timestamp", c.loop_timestamp},
         {"bow_matches", c.bow_matches},
         {"sim3_inliers", c.sim3_inliers},
         {"matches", c.loop_matches},
         {"scale", c.scale},
         {"implied_correction", c.implied_correction},
         {"allowed_correction", c.allowed_correction},
         {"path_length", c.path_length},
         {"moved", c.translation},
         {"kind", c.merge ? "map merge" : "loop"},
         {"merged_keyframes", c.merge_report.moved_keyframes},
         {"fused_points", c.merge ? c.merge_report.fused_points : c.correction.fused_points},
         {"essential_graph_keyframes", c.correction.graph_keyframes},
         {"essential_graph_edges", c.correction.graph_edges},
         {"correction_ms", c.correction_ms},
         {"global_ba_keyframes", c.global_ba.keyframes},
         {"global_ba_points", c.global_ba.points},
         {"global_ba_ms", c.global_ba.solve_ms}});
  return {{"enabled", true},
          {"vocabulary", system.vocabulary_path()},
          {"keyframes_checked", report.keyframes_checked},
          {"loops_rejected", report.loops_rejected},
          {"detection_ms", to_json(summarize(report.detection_ms))},
          {"map_lock_wait_ms", to_json(summarize(report.map_lock_wait_ms))},
          {"loops", loops}};
}

std::string own_world_file(std::size_t map_id) {
  return "trajectory_map" + std::to_string(map_id) + ".tum";
}

nlohmann::json own_worlds_json(const RunResult& result) {
  nlohmann::json maps = nlohmann::json::array();
  for (const auto& [id, frames] : result.own_world_frames)
    maps.push_back({{"map", id}, {"frames", frames}, {"file", own_world_file(id)}});
  return maps;
}

// A monocular map never merged keeps its own scale: its frames must not share a file with the
// main map's, where an alignment would fit one scale to both.
void write_own_world_trajectories(const std::string& out, const TrajectoriesByWorld& worlds,
                                  const SE3& T_cam0_image, RunResult& result) {
  for (const auto& [id, trajectory] : worlds.own_worlds) {
    spdlog::warn(
        "map {}: {} frames in a world of their own (a monocular map never merged into "
        "map {}), written to {} and not to trajectory.tum",
        id, trajectory.size(), worlds.main_map_id, own_world_file(id));
    io::write_tum_trajectory(out + own_world_file(id), to_cam0(trajectory, T_cam0_image));
    result.own_world_frames[id] = trajectory.size();
  }
}

std::string trajectory_frame(const io::DatasetGeometry& geometry, const MapFiles& files) {
  return fmt::format(
      "{}, world = {}",
      geometry.T_cam0_image.log().norm() > 0.0 ? "cam0 (unrectified left camera)" : "left camera",
      files.load.empty() ? "first pose"
                         : "the loaded map's (the first pose of the run that made it)");
}

void write_run_json(const std::string& path, const RunConfig& config, const Settings& settings,
                    const SystemOptions& options, const System& system,
                    const io::DatasetGeometry& geometry, const Playback& played,
                    const RunResult& result, const MapFiles& files) {
  nlohmann::json map_file = {{"localization_only", options.localization_only}};
  map_file["loaded"] = files.load.empty() ? nlohmann::json() : nlohmann::json(files.load);
  map_file["loaded_keyframes"] = result.loaded_keyframes;
  map_file["saved"] = files.save.empty() ? nlohmann::json() : nlohmann::json(files.save);
  map_file["saved_keyframes"] = result.saved_keyframes;
  map_file["load_ms"] = system.map_load_ms();
  map_file["save_ms"] = result.map_save_ms;
  nlohmann::json stopped_by;  // null unless a signal ended the run
  if (result.stop_signal) stopped_by = stop_signal_name(result.stop_signal);
  write_json(path,
             {{"version", SBASLAM_VERSION},
              {"settings", settings.path},
              {"dataset", {{"kind", config.dataset_kind}, {"path", config.dataset_path}}},
              {"sensor", config.sensor},
              {"image_size", {geometry.camera.width, geometry.camera.height}},
              {"resized_from", geometry.scaling ? nlohmann::json({geometry.scaling->from.width,
                                                                  geometry.scaling->from.height})
                                                : nlohmann::json()},
              {"seed", options.seed},
              {"deterministic", options.deterministic},
              {"realtime", config.realtime},
              {"saliency",
               {{"source", options.saliency},
                {"model", saliency::saliency_model_file(options.saliency, settings.saliency)},
                {"depth", settings.saliency.depth_source},
                {"weight_a", settings.saliency.weight_a},
                {"weight_b", settings.saliency.weight_b},
                {"map_ba_weight_scale", system.map_ba_weight_scale()}}},
              {"loop_closing", loop_closing_json(system)},
              {"map_file", map_file},
              {"stopped_by", stopped_by},
              {"frames", result.frames},
              {"frames_tracked", result.frames_tracked},
              {"untracked_stamps", system.untracked_stamps()},
              {"unreadable_frames", played.unreadable},
              {"keyframes", result.keyframes},
              {"map_points", result.map_points},
              {"maps", result.maps},
              {"maps_in_own_world", own_worlds_json(result)},
              {"weak_motion_model_frames", system.tracker().weak_motion_model_frames()},
              {"relocalizations", system.tracker().relocalizations()},
              {"odometry_frames", system.tracker().odometry_frames()},
              {"refused_relocalizations", system.tracker().refused_relocalizations()},
              {"status", result.status},
              {"trajectory_frame", trajectory_frame(geometry, files)}});
}

}  // namespace

RunResult run_sequence(const RunConfig& config) {
  check_run_config(config);
  Settings settings = load_settings(config.settings_path);
  if (config.loop_closing) settings.loop_closing.enabled = *config.loop_closing;
  const MapFiles files = map_files(config, settings);
  const SystemOptions options = system_options(config, settings, files);
  io::DatasetOptions dataset_options;
  dataset_options.load_right = options.stereo;
  dataset_options.load_depth = options.rgbd;
  dataset_options.settings = &settings;
  std::unique_ptr<io::DatasetReader> reader =
      io::make_dataset_reader(config.dataset_kind, config.dataset_path, dataset_options);
  if (reader->size() == 0) fail("{}: the sequence has no frames", config.dataset_path);
  std::error_code ec;
  std::filesystem::create_directories(config.out_dir, ec);
  if (ec) fail("{}: cannot create the output folder ({})", config.out_dir, ec.message());

  const io::DatasetGeometry geometry =
      io::resolve_geometry(settings, *reader, config.dataset_path, options.stereo, options.rgbd);
  if (geometry.scaling) {
    spdlog::info("images resized from {}x{} to {}x{} (Camera.newWidth/newHeight)",
                 geometry.scaling->from.width, geometry.scaling->from.height,
                 geometry.scaling->to.width, geometry.scaling->to.height);
    reader = std::make_unique<io::ResizedDataset>(std::move(reader), *geometry.scaling);
  }
  System system(settings, geometry.camera, geometry.stereo, options);
  const StopSignalGuard stop;
  const Playback played = play(system, *reader, config, stop);
  system.shutdown();

  RunResult result;
  result.stop_signal = stop.received();
  if (result.stop_signal)
    spdlog::warn("{}: stopping after {} of {} frames; writing the outputs",
                 stop_signal_name(result.stop_signal),
                 played.stamps.size() + played.unreadable.size(), played.requested);
  const TrajectoriesByWorld worlds = system.frame_trajectories();
  const Trajectory trajectory = to_cam0(worlds.main, geometry.T_cam0_image);
  const Trajectory keyframes = to_cam0(system.keyframe_trajectories().main, geometry.T_cam0_image);
  const std::string out = config.out_dir + "/";
  write_own_world_trajectories(out, worlds, geometry.T_cam0_image, result);
  io::write_tum_trajectory(out + "trajectory.tum", trajectory);
  io::write_euroc_trajectory(out + "trajectory.csv", trajectory);
  io::write_tum_trajectory(out + "keyframes.tum", keyframes);
  if (reader->kind() == "kitti")
    io::write_kitti_trajectory(out + "trajectory.kitti",
                               one_row_per_frame(trajectory, played.stamps));

  const SystemTimings timings = system.timings();
  write_timing_json(out + "timing.json", timings);
  result.frames = played.stamps.size();
  result.frames_tracked = trajectory.size();
  result.keyframes = system.keyframe_count();
  result.map_points = system.map_point_count();
  result.maps = system.maps();
  result.loops_closed = system.loop_report().loops.size();
  if (system.loaded_map()) {
    result.loaded_keyframes = system.loaded_map()->keyframes;
    result.status = result.frames_tracked > 0 || result.maps > 0
                        ? "ok"
                        : "no frame relocalised in the loaded map";
  } else {
    result.status = result.maps > 0 ? "ok" : system.initialization_status();
  }
  if (result.status != "ok") spdlog::warn("{}", result.status);
  // After the trajectory files: a map that cannot be written must not cost the trajectory.
  if (!files.save.empty()) {
    const Stopwatch saving;
    result.saved_keyframes = system.save_map(files.save).keyframes;
    result.map_save_ms = saving.elapsed_ms();
    result.saved_map = files.save;
  }
  result.tracking_median_ms = summarize(timings.tracking_ms).median;
  result.local_ba_median_ms = summarize(timings.mapping.local_ba_ms).median;
  result.trajectory = trajectory;
  write_run_json(out + "run.json", config, settings, options, system, geometry, played, result,
                 files);
  if (config.export_stable_features)
    export_stable_features(system, *reader, played.image_of_stamp, config, result);
  return result;
}

}  // namespace sbaslam
