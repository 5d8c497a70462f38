#pragma once
// Global BA after a loop correction (ORB-SLAM's RunGlobalBundleAdjustment): every keyframe and
// point of the map, with the Salient BA weights as in local BA. Ceres solves a copy while the map
// lock is released, so tracking and local mapping go on; keyframes and points they added
// meanwhile then follow the correction of their spanning-tree parent and reference keyframe.

#include <atomic>
#include <cstddef>
#include <mutex>

#include "sbaslam/map/map.h"
#include "sbaslam/optimize/bundle_adjuster.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"

namespace sbaslam::loop {

struct GlobalBundleAdjustmentReport {
  std::size_t keyframes = 0, points = 0, observations = 0;
  int iterations = 0;
  int outliers_removed = 0;
  std::size_t propagated_keyframes = 0, propagated_points = 0;  // added during the solve
  double solve_ms = 0.0;
};

// `map_lock` is held on entry and on return.
GlobalBundleAdjustmentReport run_global_bundle_adjustment(
    map::Map& map, const map::CameraRig& rig, const optimize::BundleAdjusterOptions& options,
    std::unique_lock<std::mutex>& map_lock, const optimize::MapBaWeighting& weighting = {});

}  // namespace sbaslam::loop
