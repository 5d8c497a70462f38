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

// Whether two keyframes belong to one map (the same root of the spanning tree): a new map
// started after a loss is not joined to an old one by a loop.
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

}  // namespace sbaslam::loop
