#pragma once
// Local mapping (ORB-SLAM's LocalMapping): takes the keyframes tracking inserts, links their
// points, culls recent points that do not hold up, triangulates new points with neighbouring
// keyframes, fuses duplicates, runs local BA and removes redundant keyframes.
//
// It runs on its own thread (start()/stop()), or, in deterministic mode, in lock-step: tracking's
// insert_keyframe() queues the keyframe and the system calls process_queue() right after the
// tracking step, on the same thread.

#include <pthread.h>

#include <atomic>
#include <functional>
#include <list>
#include <mutex>
#include <optional>
#include <thread>

#include "sbaslam/core/work_queue.h"
#include "sbaslam/map/map.h"
#include "sbaslam/optimize/bundle_adjuster.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"
#include "sbaslam/tracking/keyframe_sink.h"

namespace sbaslam::mapping {

struct LocalMapperOptions {
  optimize::BundleAdjusterOptions bundle_adjustment;
  optimize::MapBaWeighting weighting;           // local BA's, and global BA's after a loop
  int triangulation_neighbours = 10;            // ORB-SLAM: 10 for stereo, 20 for monocular
  double redundant_ratio = 0.9;                 // keyframe culling threshold
  std::size_t max_local_keyframes = 20;         // free keyframes of local BA besides the new one
  std::optional<double> mono_min_parallax_deg;  // MappingSettings; unset: ORB-SLAM's gate
  // With stereo, each pass of local BA ends once an iteration changes the cost by under 1 %: the
  // window starts near its optimum, and each further iteration costs ~30 ms for little (city-loop:
  // local BA 487 -> 297 ms, RPE 0.0096 -> 0.0099 m). Monocular local BA keeps every iteration: an
  // early stop was measured worse on KITTI 06. See docs/RESULTS.md, "Session 9".
  double stereo_ba_function_tolerance = 1e-2;
  // While tracking extracts features (yield_cores), the mapping thread runs under SCHED_IDLE,
  // so the two extraction threads get both cores; otherwise it runs at normal priority, so that
  // other processes cannot starve it. A nice value (5 or 19) was measured not to be enough: the
  // extraction's waking worker waited for the mapper's time slice (stereo extraction on city-loop
  // 16-17 ms instead of 11.7). Leaving SCHED_IDLE needs CAP_SYS_NICE or RLIMIT_NICE >= 20; where
  // the process cannot, the thread runs at nice 5 throughout.
  bool yield_cores_to_extraction = true;
};

// Per-keyframe timings, reported in timing.json.
struct LocalMapperTimings {
  std::vector<double> keyframe_ms;
  std::vector<double> local_ba_ms;
  // Local BAs cut short because tracking inserted a keyframe (ORB-SLAM's behaviour); their time
  // is in local_ba_ms too.
  std::size_t local_ba_interrupted = 0;
};

class LocalMapper : public tracking::KeyframeSink {
 public:
  LocalMapper(map::Map& map, const map::CameraRig& rig, LocalMapperOptions options);
  ~LocalMapper() override;

  void insert_keyframe(map::KeyFrame* kf) override;
  bool is_idle() const override;
  std::size_t queued_keyframes() const override;
  void interrupt_bundle_adjustment() override { abort_ba_ = true; }
  // Receives each keyframe once local mapping is done with it (loop closing), on the mapping
  // thread, without the map lock. Set before start().
  void set_next_stage(std::function<void(map::KeyFrame*)> next_stage) {
    next_stage_ = std::move(next_stage);
  }
  // Called by the tracking thread around feature extraction; see yield_cores_to_extraction.
  void yield_cores(bool yield);
  // Whether yield_cores has an effect (decided by start()), and the mapping thread's current
  // scheduling policy (SCHED_OTHER, SCHED_IDLE; -1 without a thread).
  bool yields_cores() const { return can_leave_idle_policy_; }
  int thread_policy() const;

  void start();          // runs the loop on a thread
  void stop();           // finishes the queue, then joins
  void process_queue();  // lock-step mode: processes everything queued, on the caller's thread
  // Blocks until the queue is empty and no keyframe is being processed (returns at once when the
  // thread is not running). Call without the map lock: mapping needs it to finish.
  void wait_until_idle();

  LocalMapperTimings timings() const;
  // What local BA runs with: the configured options, with stereo_ba_function_tolerance for a
  // stereo rig.
  optimize::BundleAdjusterOptions local_bundle_adjustment_options() const;

 private:
  void run();
  void process_keyframe(map::KeyFrame* kf);
  void link_keyframe_points(map::KeyFrame* kf);
  void cull_recent_points(map::KeyFrame* kf);
  void local_bundle_adjustment(map::KeyFrame* kf, std::unique_lock<std::mutex>& map_lock);
  void cull_keyframes(map::KeyFrame* kf);

  map::Map& map_;
  const map::CameraRig& rig_;
  LocalMapperOptions options_;

  WorkQueue<map::KeyFrame*> queue_;
  std::thread thread_;
  pthread_t thread_handle_{};                       // of thread_, for yield_cores
  std::atomic<bool> can_leave_idle_policy_{false};  // set by start()
  std::atomic<bool> abort_ba_{false};

  std::function<void(map::KeyFrame*)> next_stage_;
  std::list<map::MapPoint*> recent_points_;
  mutable std::mutex timings_mutex_;
  LocalMapperTimings timings_;
};

}  // namespace sbaslam::mapping
