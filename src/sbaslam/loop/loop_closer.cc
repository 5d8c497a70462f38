#include "sbaslam/loop/loop_closer.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>

#include "sbaslam/core/thread_policy.h"
#include "sbaslam/core/timing.h"
#include "sbaslam/loop/loop_gate.h"

namespace sbaslam::loop {

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
  queue_.push(kf);
}

void LoopCloser::start() {
  if (thread_.joinable()) return;
  queue_.reopen();
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
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void LoopCloser::run() {
  if (options_.yield_cores_to_extraction && !can_leave_idle_policy_ &&
      !lower_current_thread_priority(5))
    spdlog::debug("loop closing: could not lower the thread priority");
  while (const std::optional<map::KeyFrame*> kf = queue_.wait_and_take()) {
    process_keyframe(*kf);
    queue_.finish_item();
  }
}

std::vector<map::KeyFrame*> LoopCloser::relocalization_candidates(const cv::Mat& descriptors,
                                                                  std::size_t map_id) const {
  BowVector bow;
  FeatureVector features;
  vocabulary_.transform(descriptors, bow, features, options_.feature_levels_up);
  return detector_.relocalization_candidates(bow, map_id);
}

void LoopCloser::file_loaded_keyframes(const std::vector<map::KeyFrame*>& keyframes) {
  first_run_keyframe_ = map_.max_keyframe_id() + 1;
  for (map::KeyFrame* kf : keyframes) {
    BowVector bow;
    FeatureVector features;
    vocabulary_.transform(kf->measurements().descriptors, bow, features,
                          options_.feature_levels_up);
    detector_.file(kf, std::move(bow), std::move(features));
  }
}

void LoopCloser::process_queue() {
  while (const std::optional<map::KeyFrame*> kf = queue_.try_take()) process_keyframe(*kf);
}

void LoopCloser::process_keyframe(map::KeyFrame* kf) {
  const Stopwatch detection;
  // A keyframe's measurements never change, so its words need no lock.
  BowVector bow;
  FeatureVector features;
  vocabulary_.transform(kf->measurements().descriptors, bow, features, options_.feature_levels_up);
  // The waits are reported apart: beside monocular mapping, which holds the lock for a whole
  // keyframe, they were most of the time once reported as detection's.
  const Stopwatch first_wait;
  std::unique_lock<std::mutex> map_lock(map_.mutex());
  double waited_ms = first_wait.elapsed_ms();
  if (kf->is_bad()) return;
  // Tracking goes first between the verifications: each one is short, a whole detection is not.
  const std::optional<DetectedLoop> loop =
      detector_.process(kf, std::move(bow), std::move(features), [&] {
        const Stopwatch yield;
        map_.yield_to_tracking(map_lock);
        waited_ms += yield.elapsed_ms();
      });
  {
    std::lock_guard<std::mutex> lock(report_mutex_);
    ++report_.keyframes_checked;
    report_.detection_ms.push_back(detection.elapsed_ms() - waited_ms);
    report_.map_lock_wait_ms.push_back(waited_ms);
  }
  if (!loop) return;
  const bool joins_maps = !same_map(map_, *loop->current, *loop->loop);
  if (joins_maps && !options_.merge_maps) {
    spdlog::debug("loop from keyframe {} to {} joins two maps: not merged", kf->id(),
                  loop->loop->id());
    return;
  }
  LoopClosure closure;
  if (!accept(*loop, closure, joins_maps)) return;
  if (joins_maps) {
    merge_at_loop(*loop, closure, map_lock);
  } else {
    close_loop(*loop, closure, map_lock);
  }
}

bool LoopCloser::accept(const DetectedLoop& loop, LoopClosure& closure, bool joins_maps) {
  if (joins_maps ? plausible_merge(loop, closure) : plausible(loop, closure)) return true;
  spdlog::info(
      "{} from keyframe {} to {} rejected: it would move {} by {:.2f}, more than the {:.2f} "
      "allowed after a path of {:.2f} (LoopClosing.max_correction_ratio {})",
      joins_maps ? "map merge" : "loop", loop.current->id(), loop.loop->id(),
      joins_maps ? "the younger map" : "the keyframe", closure.implied_correction,
      closure.allowed_correction, closure.path_length, options_.max_correction_ratio);
  std::lock_guard<std::mutex> lock(report_mutex_);
  ++report_.loops_rejected;
  return false;
}

bool LoopCloser::plausible(const DetectedLoop& loop, LoopClosure& closure) const {
  const Vec3 loop_center = loop.S_cw.inverse() * Vec3::Zero();
  closure.implied_correction = (loop_center - loop.current->camera_center()).norm();
  closure.path_length = driven_path_length(map_, *loop.loop, *loop.current, first_run_keyframe_);
  closure.allowed_correction = options_.max_correction_ratio * closure.path_length;
  return options_.max_correction_ratio <= 0.0 ||
         closure.implied_correction <= closure.allowed_correction;
}

bool LoopCloser::plausible_merge(const DetectedLoop& loop, LoopClosure& closure) const {
  const MergePlan plan = plan_merge(map_, loop);
  const Vec3 root = plan.moving_root->camera_center();
  closure.implied_correction = (plan.S * root - root).norm();
  closure.path_length = driven_path_length(map_, *loop.loop, *loop.current, first_run_keyframe_);
  const Loss loss = loss_before(map_, *plan.moving_root, first_run_keyframe_);
  closure.allowed_correction = loss.anchored ? options_.max_correction_ratio * closure.path_length +
                                                   2.0 * loss.speed * loss.seconds
                                             : std::numeric_limits<double>::infinity();
  return options_.max_correction_ratio <= 0.0 ||
         closure.implied_correction <= closure.allowed_correction;
}

void LoopCloser::describe(const DetectedLoop& loop, LoopClosure& closure) const {
  closure.keyframe_id = loop.current->id();
  closure.loop_keyframe_id = loop.loop->id();
  closure.timestamp = loop.current->timestamp();
  closure.loop_timestamp = loop.loop->timestamp();
  closure.bow_matches = loop.bow_matches;
  closure.sim3_inliers = loop.sim3_inliers;
  closure.loop_matches = loop.loop_matches;
  closure.scale = loop.S_cw.scale();
}

void LoopCloser::close_loop(const DetectedLoop& loop, LoopClosure closure,
                            std::unique_lock<std::mutex>& map_lock) {
  describe(loop, closure);
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
  spdlog::info(
      "loop closed: keyframe {} (t = {:.3f}) to keyframe {} (t = {:.3f}), {} matches, moved "
      "{:.3f}, scale {:.4f}, {} keyframes in the essential graph, {:.0f} ms",
      closure.keyframe_id, closure.timestamp, closure.loop_keyframe_id, closure.loop_timestamp,
      closure.loop_matches, closure.translation, closure.scale, closure.correction.graph_keyframes,
      closure.correction_ms);
  finish(loop, closure, map_lock);
}

void LoopCloser::merge_at_loop(const DetectedLoop& loop, LoopClosure closure,
                               std::unique_lock<std::mutex>& map_lock) {
  describe(loop, closure);
  closure.merge = true;
  const Vec3 center_before = loop.current->camera_center();
  const Stopwatch correction;
  closure.merge_report = merge_maps(map_, loop);
  closure.correction_ms = correction.elapsed_ms();
  closure.translation = (loop.current->camera_center() - center_before).norm();
  spdlog::info(
      "maps merged: keyframe {} (t = {:.3f}) to keyframe {} (t = {:.3f}) of an older map, {} "
      "matches, moved {:.3f}, scale {:.4f}, {} keyframes and {} points moved, {:.0f} ms",
      closure.keyframe_id, closure.timestamp, closure.loop_keyframe_id, closure.loop_timestamp,
      closure.loop_matches, closure.translation, closure.scale,
      closure.merge_report.moved_keyframes, closure.merge_report.moved_points,
      closure.correction_ms);
  finish(loop, closure, map_lock);
}

void LoopCloser::finish(const DetectedLoop& loop, LoopClosure closure,
                        std::unique_lock<std::mutex>& map_lock) {
  detector_.loop_closed_at(*loop.current);
  if (options_.run_global_bundle_adjustment) {
    closure.global_ba =
        run_global_bundle_adjustment(map_, rig_, options_.global_bundle_adjustment, map_lock,
                                     options_.global_bundle_adjustment_weighting);
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
