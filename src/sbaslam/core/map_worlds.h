#pragma once
// Which maps' poses go into the written trajectory. Each initialisation starts a map, anchored at
// the last known pose. A stereo or RGB-D map is metric, so its anchor keeps it in the first map's
// world frame. A monocular map has its own scale (median depth 1 at its initialisation) until a
// loop merges it, so one file holding two unmerged monocular maps mixes scales, and no alignment
// can fit both. As ORB-SLAM3 writes only its biggest map, the main trajectory then holds the map
// with the most live keyframes; each other map's poses go to a file of their own.

#include <cstddef>
#include <map>
#include <vector>

#include "sbaslam/core/trajectory.h"

namespace sbaslam {

struct PoseInMap {
  double stamp = 0.0;
  SE3 pose;  // T_world_frame
  std::size_t map_id = 0;
};

struct TrajectoriesByWorld {
  std::size_t main_map_id = 0;
  Trajectory main;                               // in the input's order
  std::map<std::size_t, Trajectory> own_worlds;  // by map id; each in its map's own world
};

// `live_keyframes` counts each map's live keyframes (Map::live_keyframes_per_map); the main map is
// the one with the most (the older on a tie). With `maps_share_world` every pose is main.
TrajectoriesByWorld split_by_world(const std::vector<PoseInMap>& poses,
                                   const std::map<std::size_t, std::size_t>& live_keyframes,
                                   bool maps_share_world);

}  // namespace sbaslam
