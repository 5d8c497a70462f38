#pragma once
// Closing a detected loop (ORB-SLAM2's LoopClosing::CorrectLoop, without its global BA): the
// current keyframe and its neighbours move to the pose the loop implies, their points with them;
// the loop's points replace their duplicates; then the essential graph (spanning tree, loop edges
// and strong covisibility edges) spreads the correction over the rest of the map, and every
// point follows its reference keyframe. The map lock is held throughout, except inside the
// window the caller may open around the graph's solve.

#include <cstddef>
#include <functional>

#include "sbaslam/loop/loop_detector.h"
#include "sbaslam/map/map.h"

namespace sbaslam::loop {

struct LoopCorrectionReport {
  std::size_t moved_keyframes = 0;  // the current keyframe's neighbourhood, moved rigidly
  std::size_t fused_points = 0;     // duplicates replaced or observations added by the loop
  std::size_t graph_keyframes = 0;  // vertices of the essential graph
  std::size_t graph_edges = 0;
  double graph_initial_cost = 0.0, graph_final_cost = 0.0;
};

// The essential graph keeps covisibility edges of at least this many shared points (ORB-SLAM).
inline constexpr int kEssentialGraphMinWeight = 100;

// Whether two keyframes belong to one map (the same root of the spanning tree). A new map
// started after a loss is its own until a loop to an older one merges the two (merge_maps).
bool same_map(const map::Map& map, const map::KeyFrame& a, const map::KeyFrame& b);

// Runs the essential graph's solve it is given; the loop closer releases the map lock around it
// (the solve reads only its own copy), so tracking and local mapping go on meanwhile. Keyframes
// they make in the window take the correction of their nearest spanning-tree ancestor in the
// graph (or the current keyframe's, before local mapping links them); a pose local mapping
// changes keeps that change on top of its correction; points follow their reference keyframe.
using SolveWindow = std::function<void(const std::function<void()>& solve)>;

// fix_scale: stereo and RGB-D maps have metric scale, so the correction is rigid. Raises
// Map::big_change_index() twice: once the neighbourhood has moved, and at the end.
LoopCorrectionReport correct_loop(map::Map& map, const DetectedLoop& loop, bool fix_scale,
                                  const SolveWindow& window = {});

struct MapMergeReport {
  std::size_t moved_keyframes = 0;  // of the younger map, brought into the older one's world
  std::size_t moved_points = 0;
  std::size_t fused_points = 0;
};

// A loop between keyframes of two maps (one started after tracking was lost): ORB-SLAM3's map
// merging, without its welding BA (the loop closer's global BA follows). The maps share no
// keyframe or point, so one similarity (rigid for stereo and RGB-D, where loop.S_cw has unit
// scale) carries the younger map, with the keyframes tracking made meanwhile, into the older
// one's world exactly: the first map's world and scale, which the trajectory is written in,
// stay. The loop's points then replace their duplicates, the spanning trees join at the loop,
// and the younger map's origin stops anchoring BA. Raises Map::big_change_index() once.
MapMergeReport merge_maps(map::Map& map, const DetectedLoop& loop);

// What merge_maps will do: which map moves (the one whose root is younger) and the similarity
// from its world to the other's.
struct MergePlan {
  const map::KeyFrame* moving_root = nullptr;
  bool current_moves = true;
  Sim3 S;  // moving world -> staying world
};
MergePlan plan_merge(const map::Map& map, const DetectedLoop& loop);

}  // namespace sbaslam::loop
