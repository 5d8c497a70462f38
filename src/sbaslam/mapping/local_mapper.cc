#include "sbaslam/mapping/local_mapper.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sbaslam/core/thread_policy.h"
#include "sbaslam/mapping/fusion.h"
#include "sbaslam/mapping/triangulation.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"

namespace sbaslam::mapping {
namespace {

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

}  // namespace

LocalMapper::LocalMapper(map::Map& map, const map::CameraRig& rig, LocalMapperOptions options)
    : map_(map), rig_(rig), options_(options) {}

LocalMapper::~LocalMapper() {
  stop();
}

void LocalMapper::insert_keyframe(map::KeyFrame* kf) {
  // With the keyframe queued, before mapping can take it: a local BA that saw an empty queue
  // stops, and the new keyframe's own cannot be stopped by this flag.
  queue_.push(kf, [this] { abort_ba_ = true; });
}

bool LocalMapper::is_idle() const {
  return queue_.idle();
}

std::size_t LocalMapper::queued_keyframes() const {
  return queue_.size();
}

void LocalMapper::wait_until_idle() {
  if (thread_.joinable()) queue_.wait_until_idle();
}

void LocalMapper::yield_cores(bool yield) {
  if (!can_leave_idle_policy_ || !thread_.joinable()) return;
  if (!set_thread_policy(thread_handle_, yield ? SCHED_IDLE : SCHED_OTHER))
    spdlog::debug("local mapping: could not change the thread's policy");
}

void LocalMapper::start() {
  if (thread_.joinable()) return;
  queue_.reopen();
  can_leave_idle_policy_ = options_.yield_cores_to_extraction && can_toggle_idle_policy();
  if (options_.yield_cores_to_extraction && !can_leave_idle_policy_)
    spdlog::debug("local mapping: cannot leave SCHED_IDLE; running at nice 5");
  thread_ = std::thread([this] { run(); });
  thread_handle_ = thread_.native_handle();
}

void LocalMapper::stop() {
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void LocalMapper::run() {
  // Threads started from here (Ceres') inherit the nice value.
  if (!can_leave_idle_policy_ && !lower_current_thread_priority(5))
    spdlog::debug("local mapping: could not lower the thread priority");
  while (const std::optional<map::KeyFrame*> kf = queue_.wait_and_take()) {
    process_keyframe(*kf);
    queue_.finish_item();
  }
}

void LocalMapper::process_queue() {
  while (const std::optional<map::KeyFrame*> kf = queue_.try_take()) process_keyframe(*kf);
}

void LocalMapper::process_keyframe(map::KeyFrame* kf) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> map_lock(map_.mutex());
  // Stereo tracking must not wait for a whole keyframe's edits: the lock goes to it between
  // steps. A monocular map gets its points only from here, and tracking that overtook a
  // half-processed keyframe missed them (KITTI 06 offline: 17 keyframes wanted instead of 49,
  // ATE 0.07-0.10 m instead of 0.0225), so monocular tracking waits for the whole keyframe.
  const auto yield = [this, &map_lock] {
    if (rig_.stereo) map_.yield_to_tracking(map_lock);
  };
  link_keyframe_points(kf);
  cull_recent_points(kf);
  const int neighbours =
      rig_.stereo ? options_.triangulation_neighbours : 2 * options_.triangulation_neighbours;
  const double min_parallax_cos = rig_.stereo || !options_.mono_min_parallax_deg
                                      ? kOrbSlamMinParallaxCos
                                      : std::cos(*options_.mono_min_parallax_deg * M_PI / 180.0);
  for (map::MapPoint* mp : create_new_map_points(map_, kf, neighbours, min_parallax_cos, yield))
    recent_points_.push_back(mp);
  if (queued_keyframes() == 0) search_in_neighbours(kf, neighbours, yield);

  abort_ba_ = false;
  if (queued_keyframes() == 0 && map_.keyframe_count_in_map(kf->map_id()) > 2 && !kf->is_bad()) {
    yield();
    local_bundle_adjustment(kf, map_lock);
    yield();
    cull_keyframes(kf);
  }
  const bool passes_on = !kf->is_bad();
  map_lock.unlock();
  {
    std::lock_guard<std::mutex> lock(timings_mutex_);
    timings_.keyframe_ms.push_back(elapsed_ms(start));
  }
  if (passes_on && next_stage_) next_stage_(kf);
}

void LocalMapper::link_keyframe_points(map::KeyFrame* kf) {
  for (std::size_t i = 0; i < kf->keypoint_count(); ++i) {
    map::MapPoint* mp = kf->map_point(i);
    if (!mp || mp->is_bad()) continue;
    if (!mp->is_in_keyframe(kf)) {
      mp->add_observation(kf, i);
      mp->update_normal_and_depth();
      mp->update_descriptor();
    } else {
      recent_points_.push_back(mp);  // created by tracking for this keyframe (stereo)
    }
  }
  kf->update_connections();
}

void LocalMapper::cull_recent_points(map::KeyFrame* kf) {
  const int min_observations = rig_.stereo ? 3 : 2;
  for (auto it = recent_points_.begin(); it != recent_points_.end();) {
    map::MapPoint* mp = *it;
    const std::size_t age = kf->id() - mp->first_keyframe_id();
    if (mp->is_bad()) {
      it = recent_points_.erase(it);
    } else if (mp->found_ratio() < 0.25 ||
               (age >= 2 && mp->observation_count() <= min_observations)) {
      mp->set_bad();
      it = recent_points_.erase(it);
    } else if (age >= 3) {
      it = recent_points_.erase(it);  // mature
    } else {
      ++it;
    }
  }
}

void LocalMapper::local_bundle_adjustment(map::KeyFrame* kf,
                                          std::unique_lock<std::mutex>& map_lock) {
  const auto start = std::chrono::steady_clock::now();
  optimize::MapBundleAdjustment ba = optimize::build_local_bundle_adjustment(
      kf, rig_, options_.max_local_keyframes, options_.weighting);
  const std::size_t big_change = map_.big_change_index();
  // Tracking may run while Ceres solves the copy; see map_bundle_adjustment.h.
  map_lock.unlock();
  optimize::solve_map_bundle_adjustment(ba, local_bundle_adjustment_options(), &abort_ba_);
  const bool interrupted = abort_ba_.load();
  map_lock.lock();
  // A loop closure meanwhile moved the window: its solution belongs to the old map.
  const bool stale = map_.big_change_index() != big_change;
  const int removed = stale ? 0 : optimize::apply_map_bundle_adjustment(ba);
  const double ms = elapsed_ms(start);
  spdlog::debug(
      "local BA at keyframe {}: {} keyframes ({} fixed), {} points, {} observations, "
      "{} iterations, {} outliers removed{}, {:.1f} ms",
      kf->id(), ba.keyframes.size(),
      std::count_if(ba.problem.keyframes.begin(), ba.problem.keyframes.end(),
                    [](const optimize::BaKeyframe& k) { return k.fixed; }),
      ba.points.size(), ba.problem.observations.size(), ba.report.iterations, removed,
      stale ? " (not applied: the map was corrected meanwhile)" : "", ms);
  std::lock_guard<std::mutex> lock(timings_mutex_);
  timings_.local_ba_ms.push_back(ms);
  if (interrupted) ++timings_.local_ba_interrupted;
}

optimize::BundleAdjusterOptions LocalMapper::local_bundle_adjustment_options() const {
  optimize::BundleAdjusterOptions ba_options = options_.bundle_adjustment;
  if (rig_.stereo) ba_options.function_tolerance = options_.stereo_ba_function_tolerance;
  return ba_options;
}

void LocalMapper::cull_keyframes(map::KeyFrame* kf) {
  constexpr int kMinObservations = 3;
  for (map::KeyFrame* candidate : kf->covisibles()) {
    if (candidate->is_bad() || candidate->is_origin()) continue;
    const map::Measurements& m = candidate->measurements();
    int points = 0, redundant = 0;
    for (std::size_t i = 0; i < candidate->keypoint_count(); ++i) {
      map::MapPoint* mp = candidate->map_point(i);
      if (!mp || mp->is_bad()) continue;
      // With stereo only close points count: far ones carry little information.
      if (rig_.stereo && (m.depth[i] > rig_.th_depth || m.depth[i] < 0.0f)) continue;
      ++points;
      if (mp->observation_count() <= kMinObservations) continue;
      const int level = m.keypoints_un[i].octave;
      int seen = 0;
      for (const auto& [other, index] : mp->observations()) {
        if (other == candidate) continue;
        if (other->measurements().keypoints_un[index].octave <= level + 1) ++seen;
        if (seen >= kMinObservations) break;
      }
      if (seen >= kMinObservations) ++redundant;
    }
    if (points > 0 && redundant > options_.redundant_ratio * points) candidate->set_bad();
  }
}

int LocalMapper::thread_policy() const {
  return thread_.joinable() ? sbaslam::thread_policy(thread_handle_) : -1;
}

LocalMapperTimings LocalMapper::timings() const {
  std::lock_guard<std::mutex> lock(timings_mutex_);
  return timings_;
}

}  // namespace sbaslam::mapping
