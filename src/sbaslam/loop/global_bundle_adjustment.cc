#include "sbaslam/loop/global_bundle_adjustment.h"

#include <unordered_map>
#include <unordered_set>

#include "sbaslam/core/timing.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"

namespace sbaslam::loop {
namespace {

struct PoseChange {
  SE3 before, after;  // world-to-camera
};

using PoseChanges = std::unordered_map<const map::KeyFrame*, PoseChange>;

// Keyframes made during the solve move with their parent (ids grow, so parents come first).
std::size_t propagate_to_keyframes(map::Map& map, PoseChanges& changes) {
  std::size_t propagated = 0;
  for (map::KeyFrame* kf : map.keyframes()) {
    if (changes.count(kf) || !kf->parent()) continue;
    const auto parent = changes.find(kf->parent());
    if (parent == changes.end()) continue;
    const SE3 before = kf->T_cw();
    const SE3 after = before * parent->second.before.inverse() * parent->second.after;
    kf->set_pose(after);
    changes[kf] = {before, after};
    ++propagated;
  }
  return propagated;
}

std::size_t propagate_to_points(map::Map& map, const PoseChanges& changes,
                                const std::unordered_set<const map::MapPoint*>& solved) {
  std::size_t propagated = 0;
  for (map::MapPoint* mp : map.map_points()) {
    if (solved.count(mp) || !mp->reference_keyframe()) continue;
    const auto ref = changes.find(mp->reference_keyframe());
    if (ref == changes.end()) continue;
    mp->set_position(ref->second.after.inverse() * (ref->second.before * mp->position()));
    mp->update_normal_and_depth();
    ++propagated;
  }
  return propagated;
}

}  // namespace

GlobalBundleAdjustmentReport run_global_bundle_adjustment(
    map::Map& map, const map::CameraRig& rig, const optimize::BundleAdjusterOptions& options,
    std::unique_lock<std::mutex>& map_lock, const optimize::MapBaWeighting& weighting) {
  GlobalBundleAdjustmentReport report;
  optimize::MapBundleAdjustment ba = optimize::build_global_bundle_adjustment(map, rig, weighting);
  PoseChanges changes;
  for (std::size_t k = 0; k < ba.keyframes.size(); ++k)
    changes[ba.keyframes[k]].before = ba.problem.keyframes[k].T_cw;
  report.keyframes = ba.keyframes.size();
  report.points = ba.points.size();
  report.observations = ba.problem.observations.size();

  map_lock.unlock();
  const Stopwatch solve;
  optimize::solve_map_bundle_adjustment(ba, options);
  report.solve_ms = solve.elapsed_ms();
  map_lock.lock();

  report.iterations = ba.report.iterations;
  report.outliers_removed = optimize::apply_map_bundle_adjustment(ba);
  for (std::size_t k = 0; k < ba.keyframes.size(); ++k)
    changes[ba.keyframes[k]].after = ba.keyframes[k]->T_cw();
  report.propagated_keyframes = propagate_to_keyframes(map, changes);
  const std::unordered_set<const map::MapPoint*> solved(ba.points.begin(), ba.points.end());
  report.propagated_points = propagate_to_points(map, changes, solved);
  map.notify_big_change();
  return report;
}

}  // namespace sbaslam::loop
