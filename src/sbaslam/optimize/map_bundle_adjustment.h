#pragma once
// Local and global BA of the map. Each runs in three steps so that the map lock is held only
// while the map is read and written, not while Ceres solves:
//   1. build (lock held): copy the keyframes, points and observations into a problem;
//   2. solve (no lock): bundle_adjust on the copy;
//   3. apply (lock held): write poses and positions back and unlink outlier observations.
// Objects are never freed while the map lives, so the pointers kept across step 2 stay valid;
// anything that turned bad meanwhile is skipped in step 3.

#include <atomic>
#include <optional>
#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/map/map.h"
#include "sbaslam/optimize/bundle_adjuster.h"

namespace sbaslam::optimize {

// Where a map BA takes each observation's Salient BA weight from. Unset: the weight stored with
// the keypoint. Set (SaliencySettings::map_ba_point_depth): recomputed from the keypoint's S_init
// and the point's depth in the keyframe as the problem is built (saliency::point_depth_weight);
// observations of keyframes that kept no S_init keep their stored weight.
struct MapBaWeighting {
  std::optional<SaliencySettings> point_depth;
};

// The D floor of point-depth weights in keyframe `kf`: Saliency.depth_near when set and positive;
// set to 0, the keyframe's nearest point; unset, the rig's close-point threshold for stereo and
// RGB-D, the keyframe's median scene depth for monocular (as the frame's map floors D). <= 0 when
// the keyframe sees no point in front of it.
double point_depth_near(const map::KeyFrame& kf, const map::CameraRig& rig,
                        const SaliencySettings& settings);

struct MapBundleAdjustment {
  BundleAdjustmentProblem problem;
  std::vector<map::KeyFrame*> keyframes;          // parallel to problem.keyframes
  std::vector<map::MapPoint*> points;             // parallel to problem.points
  std::vector<std::size_t> observation_keypoint;  // keypoint index per observation
  BundleAdjustmentReport report;
};

// ORB-SLAM's local BA window around `kf`: kf and its covisible keyframes free, the other
// keyframes that see their points fixed (as are origin keyframes). Unlike ORB-SLAM, the free
// keyframes are capped at the `max_local_keyframes` strongest covisibles: on long straight
// drives distant points link nearly every keyframe, and an uncapped window grows without bound.
MapBundleAdjustment build_local_bundle_adjustment(map::KeyFrame* kf, const map::CameraRig& rig,
                                                  std::size_t max_local_keyframes,
                                                  const MapBaWeighting& weighting = {});

// Every keyframe and point of the map; origin keyframes fixed.
MapBundleAdjustment build_global_bundle_adjustment(map::Map& map, const map::CameraRig& rig,
                                                   const MapBaWeighting& weighting = {});
// The given keyframes and all their points (e.g. the two keyframes of a monocular
// initialisation); origin keyframes fixed.
MapBundleAdjustment build_bundle_adjustment(const std::vector<map::KeyFrame*>& keyframes,
                                            const map::CameraRig& rig,
                                            const MapBaWeighting& weighting = {});

void solve_map_bundle_adjustment(MapBundleAdjustment& ba, const BundleAdjusterOptions& options,
                                 const std::atomic<bool>* abort = nullptr);

// Returns the number of observations removed as outliers.
int apply_map_bundle_adjustment(MapBundleAdjustment& ba);

}  // namespace sbaslam::optimize
