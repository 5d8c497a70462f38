#pragma once
// Wiring of the SLAM pipeline: frame -> saliency -> front end -> tracking -> local mapping ->
// loop closing (when the settings ask for it). No algorithm lives here. In deterministic mode
// local mapping and loop closing run in lock-step on the caller's thread after each tracking
// step, so the same input and seed give bit-identical output.

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "sbaslam/core/map_worlds.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/core/trajectory.h"
#include "sbaslam/loop/loop_closer.h"
#include "sbaslam/map/map.h"
#include "sbaslam/map/map_file.h"
#include "sbaslam/mapping/local_mapper.h"
#include "sbaslam/saliency/saliency_source.h"
#include "sbaslam/saliency/velodyne_depth.h"
#include "sbaslam/tracking/measurement_builder.h"
#include "sbaslam/tracking/tracker.h"

namespace sbaslam {

struct SystemOptions {
  // A rectified stereo pair, or a depth image registered to the left image; either gives the
  // keypoints depth (the rig is a stereo one, see make_camera_rig).
  bool stereo = true;
  bool rgbd = false;
  bool deterministic = false;
  std::uint64_t seed = 0;
  // Where each frame's saliency map comes from: "none" (uniform BA), "model" (the shipped ONNX
  // model, or Saliency.model), or a folder of precomputed maps named like the images. The same
  // default as SaliencySettings::source.
  std::string saliency = "model";
  // Offline playback (threaded, frames as fast as they load): when local mapping was too busy for
  // the keyframe the last frame wanted, the next frame waits for mapping before it is tracked
  // (its extraction still overlaps), and the last frame then gets its keyframe if it still
  // qualifies, as in lock-step mode. ORB-SLAM's rule refuses the keyframe outright, which is right
  // at the camera's rate but starves the map whenever frames arrive faster than mapping (a loaded
  // machine, or no real-time pacing): KITTI 06 monocular lost 3 of 5 runs that way, and a stereo
  // run whose mapper yielded the cores to tracking (city-loop, 300 frames) had a 1-frame RPE of
  // 0.0148 m without the wait and 0.0107 m with it.
  bool wait_for_mapping = true;
  // A map saved by an earlier run (map_file.h) to start from: the first frame relocalises in it
  // (its biggest map) through loop closing's keyframe database, which then holds its keyframes
  // even with loop closing off. With localization_only (ORB-SLAM3's localization mode) the map
  // stays as loaded: no keyframes, no local mapping, no loops, and a lost frame only
  // relocalises. Otherwise mapping goes on from it, as after a loss.
  std::string map_to_load;
  bool localization_only = false;
  // max_frames_between_keyframes comes from Camera.fps when the settings give it.
  tracking::TrackerOptions tracker;
};

struct SystemTimings {
  std::vector<double> tracking_ms;  // whole per-frame step, extraction included
  // Front end until the frame's measurements are ready: ORB, stereo matching, depth correction
  // and weights. Monocular and RGB-D frames predict the saliency map beside ORB extraction, so
  // for them this includes only the part of inference that extraction does not hide.
  std::vector<double> extraction_ms;
  std::vector<double> saliency_ms;  // predicting the frame's saliency map, on its own (0: "none")
  std::vector<double> mapping_wait_ms;  // per frame, not part of tracking_ms (wait_for_mapping)
  tracking::TrackerTimings tracking;
  mapping::LocalMapperTimings mapping;
};

class System {
 public:
  // `camera` and `stereo` describe the images process() receives (rectified for stereo).
  System(const Settings& settings, const CameraSettings& camera, const StereoSettings& stereo,
         const SystemOptions& options);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // `left_path` lets a folder of precomputed saliency maps find the frame's map. `depth` is the
  // raw depth image of an RGB-D frame (options.rgbd), registered to `left`.
  tracking::TrackingState process(double timestamp, const cv::Mat& left, const cv::Mat& right,
                                  const std::string& left_path = std::string(),
                                  const cv::Mat& depth = cv::Mat());
  // Lets local mapping finish its queue and stops its thread. Idempotent.
  void shutdown();

  // Every frame with a pose, T_world_camera, placed through its reference keyframe so that later
  // keyframe corrections apply, split by world (split_by_world: a monocular map never merged
  // into the biggest one is in a world of its own). The main world is the first keyframe's camera.
  TrajectoriesByWorld frame_trajectories() const;
  TrajectoriesByWorld keyframe_trajectories() const;
  Trajectory frame_trajectory() const { return frame_trajectories().main; }
  // Stamps of frames that have no pose (before initialisation, or lost).
  std::vector<double> untracked_stamps() const;

  SystemTimings timings() const;
  double last_tracking_ms() const { return tracking_ms_.empty() ? 0.0 : tracking_ms_.back(); }
  std::size_t keyframe_count() const;
  std::size_t map_point_count() const;
  int maps() const { return tracker_->maps_started(); }
  // Empty once a map exists; otherwise why not (e.g. "not initialised: insufficient parallax").
  std::string initialization_status() const { return tracker_->initialization_status(); }
  const map::CameraRig& rig() const { return rig_; }
  // The factor local and full BA multiply the Salient BA weights by (1 for uniform BA).
  double map_ba_weight_scale() const { return map_ba_weight_scale_; }
  const tracking::Tracker& tracker() const { return *tracker_; }
  // Loops are looked for (Settings::loop_closing, and not localization_only).
  bool loop_closing() const { return detect_loops_; }
  const std::string& vocabulary_path() const { return vocabulary_path_; }
  loop::LoopCloserReport loop_report() const;
  // Calls `reader` with the map, holding the map lock for the whole call (e.g. to export map
  // points at the end of a run). After shutdown() no other thread reads or writes the map.
  void read_map(const std::function<void(const map::Map&)>& reader) const;
  // What SystemOptions::map_to_load held (empty without one).
  const std::optional<map::MapFileSummary>& loaded_map() const { return loaded_map_; }
  // Reading the file and filing its keyframes for place recognition.
  double map_load_ms() const { return map_load_ms_; }
  // Writes the map (map_file.h); call after shutdown(), or the file may miss the last keyframes.
  map::MapFileSummary save_map(const std::string& path) const;

 private:
  // The keyframe database serves relocalisation; with detect_loops keyframes also come from
  // local mapping and loops are closed.
  void start_loop_closing(const LoopClosingSettings& settings,
                          const mapping::LocalMapperOptions& mapper_options, bool detect_loops);
  void load_map(const std::string& path);

  SystemOptions options_;
  map::CameraRig rig_;
  mutable map::Map map_;  // mutable: const readers still take its lock
  std::unique_ptr<saliency::SaliencySource> saliency_;
  std::unique_ptr<tracking::MeasurementBuilder> builder_;
  // With saliency on, the inference is one of the extraction's parallel tasks.
  bool predict_among_extraction_tasks_ = false;
  // Monocular frames with Saliency.depth "auto" take Algorithm 1's D from the tracked map.
  bool predict_mono_depths_ = false;
  double map_ba_weight_scale_ = 1.0;
  std::unique_ptr<saliency::VelodyneDepth> velodyne_;  // Saliency.depth "velodyne"
  std::unique_ptr<mapping::LocalMapper> mapper_;
  std::unique_ptr<tracking::Tracker> tracker_;
  std::string vocabulary_path_;
  std::unique_ptr<loop::Vocabulary> vocabulary_;
  std::unique_ptr<loop::LoopCloser> loop_closer_;
  bool detect_loops_ = false;
  std::optional<map::MapFileSummary> loaded_map_;
  double map_load_ms_ = 0.0;
  std::size_t next_frame_id_ = 0;
  std::vector<double> tracking_ms_;
  std::vector<double> extraction_ms_;
  std::vector<double> saliency_ms_;
  std::vector<double> mapping_wait_ms_;
  bool wait_for_mapping_ = false;
  bool running_ = false;
};

}  // namespace sbaslam
