#include "sbaslam/system.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <mutex>
#include <optional>

#include "sbaslam/core/error.h"
#include "sbaslam/core/shipped_file.h"
#include "sbaslam/core/timing.h"

namespace sbaslam {
namespace {

// Keeps the mapping thread off the cores while the front end runs (LocalMapper::yield_cores),
// also when the front end throws.
// The helper threads step aside (SCHED_IDLE) while tracking extracts features.
class CoresYielded {
 public:
  CoresYielded(mapping::LocalMapper& mapper, loop::LoopCloser* loop_closer)
      : mapper_(mapper), loop_closer_(loop_closer) {
    mapper_.yield_cores(true);
    if (loop_closer_) loop_closer_->yield_cores(true);
  }
  ~CoresYielded() {
    mapper_.yield_cores(false);
    if (loop_closer_) loop_closer_->yield_cores(false);
  }
  CoresYielded(const CoresYielded&) = delete;
  CoresYielded& operator=(const CoresYielded&) = delete;

 private:
  mapping::LocalMapper& mapper_;
  loop::LoopCloser* loop_closer_;
};

}  // namespace

System::System(const Settings& settings, const CameraSettings& camera, const StereoSettings& stereo,
               const SystemOptions& options)
    : options_(options),
      rig_(tracking::make_camera_rig(camera, stereo, settings.orb, options.stereo, options.rgbd)) {
  saliency_ = saliency::make_saliency_source(options.saliency, settings.saliency);
  // Inference runs as one more of the extraction's parallel tasks (MeasurementBuilder::extract).
  predict_among_extraction_tasks_ = options.saliency != "none";
  builder_ = std::make_unique<tracking::MeasurementBuilder>(rig_, settings.orb, settings.saliency,
                                                            settings.rgbd);
  predict_mono_depths_ =
      options.saliency != "none" && !rig_.stereo && settings.saliency.depth_source == "auto";
  if (settings.saliency.depth_source == "velodyne")
    velodyne_ = std::make_unique<saliency::VelodyneDepth>(rig_.camera.intrinsics(),
                                                          cv::Size(camera.width, camera.height));
  wait_for_mapping_ = options.wait_for_mapping && !options.deterministic;

  mapping::LocalMapperOptions mapper_options;
  // One thread: yield_cores switches the policy of the mapping thread alone, and a second BA
  // thread gained only 16 % on the bench (607 vs 722 ms).
  mapper_options.bundle_adjustment.num_threads = 1;
  mapper_options.mono_min_parallax_deg = settings.mapping.mono_min_parallax_deg;
  // Uniform BA (every weight 1) keeps ORB-SLAM's kernel in every BA.
  if (options.saliency != "none") map_ba_weight_scale_ = settings.saliency.map_ba_weight_scale();
  mapper_options.bundle_adjustment.weight_scale = map_ba_weight_scale_;
  if (options.saliency != "none" && settings.saliency.map_ba_point_depth(rig_.stereo))
    mapper_options.weighting.point_depth = settings.saliency;
  mapper_ = std::make_unique<mapping::LocalMapper>(map_, rig_, mapper_options);

  tracking::TrackerOptions tracker_options = options.tracker;
  tracker_options.map_ba_weight_scale = map_ba_weight_scale_;
  tracker_options.map_ba_weighting = mapper_options.weighting;
  tracker_options.localization_only = options.localization_only;
  if (camera.fps > 0.0)
    tracker_options.max_frames_between_keyframes = static_cast<int>(std::lround(camera.fps));
  tracker_ =
      std::make_unique<tracking::Tracker>(map_, rig_, *mapper_, tracker_options, options.seed);
  const bool detect_loops = settings.loop_closing.enabled && !options.localization_only;
  if (detect_loops || !options.map_to_load.empty())
    start_loop_closing(settings.loop_closing, mapper_options, detect_loops);
  if (!options.map_to_load.empty()) load_map(options.map_to_load);
  if (!options.deterministic && !options.localization_only) {
    mapper_->start();
    if (detect_loops_) loop_closer_->start();
    running_ = true;
  }
}

void System::load_map(const std::string& path) {
  const Stopwatch loading;
  std::lock_guard<std::mutex> lock(map_.mutex());
  loaded_map_ = map::load_map(path, rig_, map_);
  if (loaded_map_->keyframes == 0) fail("{}: the map file holds no keyframe", path);
  const std::vector<map::KeyFrame*> keyframes = map_.keyframes();
  loop_closer_->file_loaded_keyframes(keyframes);
  // Frame ids stay unique in the map: the loaded keyframes keep those of the run that made them.
  next_frame_id_ = loaded_map_->max_frame_id + 1;
  map::KeyFrame* newest = nullptr;
  for (map::KeyFrame* kf : keyframes)
    if (kf->map_id() == loaded_map_->biggest_map_id) newest = kf;
  tracker_->start_in_loaded_map(newest, next_frame_id_);
  map_load_ms_ = loading.elapsed_ms();
  spdlog::info("{}: loaded {} keyframes and {} map points in {} map(s)", path,
               loaded_map_->keyframes, loaded_map_->map_points, loaded_map_->maps);
}

map::MapFileSummary System::save_map(const std::string& path) const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  return map::save_map(map_, rig_, path);
}

void System::start_loop_closing(const LoopClosingSettings& settings,
                                const mapping::LocalMapperOptions& mapper_options,
                                bool detect_loops) {
  detect_loops_ = detect_loops;
  vocabulary_path_ = settings.vocabulary_path.empty()
                         ? shipped_file_path("orb_vocabulary.bin", "ORB vocabulary")
                         : settings.vocabulary_path;
  vocabulary_ = std::make_unique<loop::Vocabulary>(loop::Vocabulary::load(vocabulary_path_));
  loop::LoopCloserOptions loop_options;
  loop_options.detection.seed = options_.seed;
  loop_options.merge_maps = settings.merge_maps;
  // ORB-SLAM's global BA: one robust pass of 10 iterations, with local BA's weights.
  loop_options.global_bundle_adjustment = mapper_options.bundle_adjustment;
  loop_options.global_bundle_adjustment.iterations = 10;
  loop_options.global_bundle_adjustment.refine_iterations = 0;
  loop_options.global_bundle_adjustment_weighting = mapper_options.weighting;
  loop_closer_ = std::make_unique<loop::LoopCloser>(map_, rig_, *vocabulary_, loop_options);
  if (detect_loops)
    mapper_->set_next_stage([this](map::KeyFrame* kf) { loop_closer_->insert_keyframe(kf); });
  tracker_->set_place_recognition([this](const tracking::Frame& frame, std::size_t map_id) {
    return loop_closer_->relocalization_candidates(frame.m().descriptors, map_id);
  });
}

System::~System() {
  shutdown();
}

void System::shutdown() {
  if (running_) {
    mapper_->stop();
    if (detect_loops_) loop_closer_->stop();
  }
  running_ = false;
}

tracking::TrackingState System::process(double timestamp, const cv::Mat& left, const cv::Mat& right,
                                        const std::string& left_path, const cv::Mat& depth) {
  const Stopwatch total;
  std::vector<saliency::DepthSample> depth_samples;
  if (predict_mono_depths_) depth_samples = tracker_->predicted_point_depths();
  std::optional<CoresYielded> cores_yielded(std::in_place, *mapper_,
                                            detect_loops_ ? loop_closer_.get() : nullptr);
  const Stopwatch front_end;
  cv::Mat saliency_map;
  tracking::ExtractedFrame extracted;
  double inference_ms = 0.0;
  const auto predict = [&] {
    const Stopwatch inference;
    saliency_map = saliency_->predict(left, timestamp, left_path);
    inference_ms = inference.elapsed_ms();
  };
  if (predict_among_extraction_tasks_) {
    extracted = builder_->extract(left, right, depth, predict);
  } else {
    predict();  // the uniform source: an empty map, at once
    extracted = builder_->extract(left, right, depth);
  }
  saliency_ms_.push_back(inference_ms);
  if (velodyne_ && !saliency_map.empty()) {
    if (left_path.empty())
      throw Error("Saliency.depth \"velodyne\" needs each frame's image path (a KITTI sequence)");
    depth_samples = velodyne_->samples_for(left_path);
  }
  builder_->weigh(extracted, left, saliency_map, depth_samples);
  map::MeasurementsPtr m = std::move(extracted.measurements);
  cores_yielded.reset();
  // Inference among extraction's tasks counts only where it delays it.
  extraction_ms_.push_back(front_end.elapsed_ms() -
                           (predict_among_extraction_tasks_ ? 0.0 : inference_ms));
  const Stopwatch wait;
  const bool deferred = wait_for_mapping_ && tracker_->keyframe_deferred();
  if (deferred) mapper_->wait_until_idle();
  mapping_wait_ms_.push_back(wait.elapsed_ms());
  // The keyframe goes to the frame that wanted it, as in lock-step mode, not to this one.
  if (deferred) tracker_->insert_deferred_keyframe();
  const tracking::TrackingState state =
      tracker_->track(tracking::Frame(next_frame_id_++, timestamp, std::move(m)));
  tracking_ms_.push_back(total.elapsed_ms() - mapping_wait_ms_.back());
  if (options_.deterministic) {
    mapper_->process_queue();
    if (detect_loops_) loop_closer_->process_queue();
  }
  return state;
}

TrajectoriesByWorld System::frame_trajectories() const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  std::vector<PoseInMap> poses;
  for (const tracking::FrameRecord& r : tracker_->records()) {
    if (!r.reference) continue;
    // A culled reference keyframe is replaced by its parent, composing the stored offsets.
    const map::KeyFrame* kf = r.reference;
    SE3 T_cr = r.T_cr;
    while (kf->is_bad() && kf->parent()) {
      T_cr = T_cr * kf->T_cp();
      kf = kf->parent();
    }
    poses.push_back({r.timestamp, (T_cr * kf->T_cw()).inverse(), kf->map_id()});
  }
  return split_by_world(poses, map_.live_keyframes_per_map(), rig_.stereo);
}

TrajectoriesByWorld System::keyframe_trajectories() const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  std::vector<PoseInMap> poses;
  for (const map::KeyFrame* kf : map_.keyframes())
    poses.push_back({kf->timestamp(), kf->T_wc(), kf->map_id()});
  return split_by_world(poses, map_.live_keyframes_per_map(), rig_.stereo);
}

std::vector<double> System::untracked_stamps() const {
  std::vector<double> stamps;
  for (const tracking::FrameRecord& r : tracker_->records())
    if (!r.reference) stamps.push_back(r.timestamp);
  return stamps;
}

SystemTimings System::timings() const {
  return {tracking_ms_,     extraction_ms_,      saliency_ms_,
          mapping_wait_ms_, tracker_->timings(), mapper_->timings()};
}

loop::LoopCloserReport System::loop_report() const {
  return detect_loops_ ? loop_closer_->report() : loop::LoopCloserReport{};
}

std::size_t System::keyframe_count() const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  return map_.keyframe_count();
}

void System::read_map(const std::function<void(const map::Map&)>& reader) const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  reader(map_);
}

std::size_t System::map_point_count() const {
  std::lock_guard<std::mutex> lock(map_.mutex());
  return map_.map_point_count();
}

}  // namespace sbaslam
