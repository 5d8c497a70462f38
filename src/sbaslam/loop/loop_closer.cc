#include "sbaslam/loop/loop_closer.h"

#include <spdlog/spdlog.h>

#include "sbaslam/core/thread_policy.h"
#include "sbaslam/core/timing.h"

namespace sbaslam::loop {
namespace {

// Along the keyframes from `from` to `to`, in the order they were made.
double path_length(const map::Map& map, const map::KeyFrame& from, const map::KeyFrame& to) {
  double length = 0.0;
  const map::KeyFrame* previous = nullptr;
  for (const map::KeyFrame* kf : map.keyframes()) {
    if (kf->id() < from.id() || kf->id() > to.id() || kf->is_bad()) continue;
    if (previous) length += (kf->camera_center() - previous->camera_center()).norm();
    previous = kf;
  }
  return length;
}

}  // namespace

LoopCloser::LoopCloser(map::Map& map, const map::CameraRig& rig, const Vocabulary& vocabulary,
                       LoopCloserOptions options)
    : map_(map),
      rig_(rig),
      vocabulary_(vocabulary),
      options_(options),
      detector_(rig, options.detection) {}

LoopCloser::~LoopCloser() {
  stop();
}

void LoopCloser::insert_keyframe(map::KeyFrame* kf) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(kf);
  }
  queue_cv_.notify_one();
}

void LoopCloser::start() {
  if (thread_.joinable()) return;
  stopping_ = false;
  can_leave_idle_policy_ = options_.yield_cores_to_extraction && can_toggle_idle_policy();
  thread_ = std::thread([this] { run(); });
  thread_handle_ = thread_.native_handle();
}

void LoopCloser::yield_cores(bool yield) {
  if (!can_leave_idle_policy_ || !thread_.joinable()) return;
  if (!set_thread_policy(thread_handle_, yield ? SCHED_IDLE : SCHED_OTHER))
    spdlog::debug("loop closing: could not change the thread's policy");
}

int LoopCloser::thread_policy() const {
  return thread_.joinable() ? sbaslam::thread_policy(thread_handle_) : -1;
}

void LoopCloser::stop() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queue_cv_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void LoopCloser::run() {
  if (options_.yield_cores_to_extraction && !can_leave_idle_policy_ &&
      !lower_current_thread_priority(5))
    spdlog::debug("loop closing: could not lower the thread priority");
  for (;;) {
    map::KeyFrame* kf = nullptr;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      kf = queue_.front();
      queue_.pop_front();
    }
    process_keyframe(kf);
  }
}

void LoopCloser::process_queue() {
  for (;;) {
    map::KeyFrame* kf = nullptr;
    {
      std::lock_guard<std::mutex> lock(queue_mutex_);
      if (queue_.empty()) return;
      kf = queue_.front();
      queue_.pop_front();
    }
    process_keyframe(kf);
  }
}

void LoopCloser::process_keyframe(map::KeyFrame* kf) {
  const Stopwatch detection;
  // A keyframe's measurements never change, so its words need no lock.
  BowVector bow;
  FeatureVector features;
  vocabulary_.transform(kf->measurements().descriptors, bow, features, options_.feature_levels_up);
  std::unique_lock<std::mutex> map_lock(map_.mutex());
  if (kf->is_bad()) return;
  // Tracking goes first between the verifications: each one is short, a whole detection is not.
  const std::optional<DetectedLoop> loop = detector_.process(
      kf, std::move(bow), std::move(features), [&] { map_.yield_to_tracking(map_lock); });
  {
    std::lock_guard<std::mutex> lock(report_mutex_);
    ++report_.keyframes_checked;
    report_.detection_ms.push_back(detection.elapsed_ms());
  }
  if (!loop) return;
  if (!same_map(map_, *loop->current, *loop->loop)) {
    spdlog::debug("loop from keyframe {} to {} joins two maps: not closed", kf->id(),
                  loop->loop->id());
    return;
  }
  LoopClosure closure;
  if (!plausible(*loop, closure)) {
    spdlog::info(
        "loop from keyframe {} to {} rejected: it would move the keyframe by {:.2f} after a path "
        "of {:.2f} (LoopClosing.max_correction_ratio {})",
        kf->id(), loop->loop->id(), closure.implied_correction, closure.path_length,
        options_.max_correction_ratio);
    std::lock_guard<std::mutex> lock(report_mutex_);
    ++report_.loops_rejected;
    return;
  }
  close_loop(*loop, closure, map_lock);
}

bool LoopCloser::plausible(const DetectedLoop& loop, LoopClosure& closure) const {
  const Vec3 loop_center = loop.S_cw.inverse() * Vec3::Zero();
  closure.implied_correction = (loop_center - loop.current->camera_center()).norm();
  closure.path_length = path_length(map_, *loop.loop, *loop.current);
  return options_.max_correction_ratio <= 0.0 ||
         closure.implied_correction <= options_.max_correction_ratio * closure.path_length;
}

void LoopCloser::close_loop(const DetectedLoop& loop, LoopClosure closure,
                            std::unique_lock<std::mutex>& map_lock) {
  closure.keyframe_id = loop.current->id();
  closure.loop_keyframe_id = loop.loop->id();
  closure.timestamp = loop.current->timestamp();
  closure.loop_timestamp = loop.loop->timestamp();
  closure.bow_matches = loop.bow_matches;
  closure.sim3_inliers = loop.sim3_inliers;
  closure.loop_matches = loop.loop_matches;
  closure.scale = loop.S_cw.scale();
  const Vec3 center_before = loop.current->camera_center();
  const Stopwatch correction;
  closure.correction =
      correct_loop(map_, loop, rig_.stereo, [&](const std::function<void()>& solve) {
        map_lock.unlock();
        solve();
        map_lock.lock();
      });
  closure.correction_ms = correction.elapsed_ms();
  closure.translation = (loop.current->camera_center() - center_before).norm();
  detector_.loop_closed_at(*loop.current);
  spdlog::info(
      "loop closed: keyframe {} (t = {:.3f}) to keyframe {} (t = {:.3f}), {} matches, moved "
      "{:.3f}, scale {:.4f}, {} keyframes in the essential graph, {:.0f} ms",
      closure.keyframe_id, closure.timestamp, closure.loop_keyframe_id, closure.loop_timestamp,
      closure.loop_matches, closure.translation, closure.scale, closure.correction.graph_keyframes,
      closure.correction_ms);
  if (options_.run_global_bundle_adjustment) {
    closure.global_ba =
        run_global_bundle_adjustment(map_, rig_, options_.global_bundle_adjustment, map_lock);
    spdlog::info("global BA: {} keyframes, {} points, {} iterations, {:.0f} ms",
                 closure.global_ba.keyframes, closure.global_ba.points,
                 closure.global_ba.iterations, closure.global_ba.solve_ms);
  }
  std::lock_guard<std::mutex> lock(report_mutex_);
  report_.loops.push_back(closure);
}

LoopCloserReport LoopCloser::report() const {
  std::lock_guard<std::mutex> lock(report_mutex_);
  return report_;
}

}  // namespace sbaslam::loop
