#pragma once
// Loop closing, the third thread of ORB-SLAM: local mapping hands it each keyframe it is done
// with; it files the keyframe's bag of words, looks for a loop (LoopDetector), corrects the map
// along it (correct_loop) and runs a global BA with the Salient BA weights.
//
// Like local mapping it runs on its own thread (start()/stop()) or, in deterministic mode, in
// lock-step: the system calls process_queue() after local mapping's, on the caller's thread.

#include <pthread.h>

#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

#include "sbaslam/core/work_queue.h"
#include "sbaslam/loop/global_bundle_adjustment.h"
#include "sbaslam/loop/loop_correction.h"
#include "sbaslam/loop/loop_detector.h"
#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/optimize/bundle_adjuster.h"

namespace sbaslam::loop {

struct LoopCloserOptions {
  LoopDetectorOptions detection;
  // ORB-SLAM's global BA: 10 iterations; weight_scale as local BA's.
  optimize::BundleAdjusterOptions global_bundle_adjustment;
  optimize::MapBaWeighting global_bundle_adjustment_weighting;
  bool run_global_bundle_adjustment = true;
  // A loop may move the current keyframe by at most this share of the path driven since the loop
  // keyframe (0: no limit). Odometry drifts by a few per cent at most; a place that merely looks
  // the same (a repeated facade, or the synthetic city, whose blocks repeat every 120 m) passes
  // every check of detection but implies a jump of a whole period. See docs/RESULTS.md.
  // A map merge may move the younger map's root by this share of the path plus twice the way
  // the camera went at its last known speed while tracking was lost (the younger map was
  // anchored at the last known pose).
  double max_correction_ratio = 0.05;
  // Keypoints are filed under their vocabulary node this many levels above the word (the
  // feature vector that BoW matching compares; ORB-SLAM: 4 of its vocabulary's 6 levels).
  int feature_levels_up = 2;
  // As local mapping's (LocalMapperOptions): SCHED_IDLE while tracking extracts features.
  bool yield_cores_to_extraction = true;
  // A loop to a keyframe of another map (one started after tracking was lost) merges the two
  // (merge_maps); off: such a loop is ignored.
  bool merge_maps = true;
};

// One closed loop or map merge, as run.json reports it.
struct LoopClosure {
  std::size_t keyframe_id = 0, loop_keyframe_id = 0;
  double timestamp = 0.0, loop_timestamp = 0.0;
  int bow_matches = 0, sim3_inliers = 0, loop_matches = 0;
  double scale = 1.0;  // of the correction (1 for stereo)
  // How far the loop puts the current keyframe from its pose (for a merge: how far it moves the
  // younger map's root), and how far the gate let it (max_correction_ratio).
  double implied_correction = 0.0;
  double allowed_correction = 0.0;
  double path_length = 0.0;  // driven from the loop keyframe to the current one
  double translation = 0.0;  // how far the current keyframe moved, map units
  LoopCorrectionReport correction;
  bool merge = false;  // the loop joined two maps: merge_report, not correction, says what moved
  MapMergeReport merge_report;
  GlobalBundleAdjustmentReport global_ba;
  double correction_ms = 0.0;
};

struct LoopCloserReport {
  std::size_t keyframes_checked = 0;
  std::size_t loops_rejected = 0;        // found (loops or merges), but implying too large a jump
  std::vector<double> detection_ms;      // per keyframe: BoW, query and verification
  std::vector<double> map_lock_wait_ms;  // per keyframe: detection's waits for the map lock
  std::vector<LoopClosure> loops;
};

class LoopCloser {
 public:
  // The vocabulary outlives the closer.
  LoopCloser(map::Map& map, const map::CameraRig& rig, const Vocabulary& vocabulary,
             LoopCloserOptions options);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  void insert_keyframe(map::KeyFrame* kf);  // any thread, without the map lock
  // Files the keyframes of a loaded map (map_file.h) for place recognition and later loops, without
  // looking for loops among them. Before start(); the caller holds the map lock.
  void file_loaded_keyframes(const std::vector<map::KeyFrame*>& keyframes);
  void start();
  void stop();           // finishes the queue, then joins
  void process_queue();  // lock-step mode
  LoopCloserReport report() const;
  // Place recognition for tracking's relocalisation: the keyframes of map `map_id` whose words
  // look like those of `descriptors` (a lost frame's), best first. Only keyframes loop closing has
  // already checked are filed. The caller (the tracking thread) holds the map lock.
  std::vector<map::KeyFrame*> relocalization_candidates(const cv::Mat& descriptors,
                                                        std::size_t map_id) const;
  // Called by the tracking thread around feature extraction, as LocalMapper::yield_cores.
  void yield_cores(bool yield);
  bool yields_cores() const { return can_leave_idle_policy_; }
  int thread_policy() const;  // -1 without a thread

 private:
  void run();
  void process_keyframe(map::KeyFrame* kf);
  bool plausible(const DetectedLoop& loop, LoopClosure& closure) const;
  bool plausible_merge(const DetectedLoop& loop, LoopClosure& closure) const;
  bool accept(const DetectedLoop& loop, LoopClosure& closure, bool joins_maps);
  void close_loop(const DetectedLoop& loop, LoopClosure closure,
                  std::unique_lock<std::mutex>& map_lock);
  void merge_at_loop(const DetectedLoop& loop, LoopClosure closure,
                     std::unique_lock<std::mutex>& map_lock);
  void describe(const DetectedLoop& loop, LoopClosure& closure) const;
  void finish(const DetectedLoop& loop, LoopClosure closure,
              std::unique_lock<std::mutex>& map_lock);

  map::Map& map_;
  const map::CameraRig& rig_;
  const Vocabulary& vocabulary_;
  LoopCloserOptions options_;
  LoopDetector detector_;

  // Keyframes with lower ids came from a loaded map (loop_gate.h); 0 without one.
  std::size_t first_run_keyframe_ = 0;

  WorkQueue<map::KeyFrame*> queue_;
  std::thread thread_;
  pthread_t thread_handle_{};
  std::atomic<bool> can_leave_idle_policy_{false};  // set by start()

  mutable std::mutex report_mutex_;
  LoopCloserReport report_;
};

}  // namespace sbaslam::loop
