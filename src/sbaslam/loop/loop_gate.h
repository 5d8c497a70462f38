#pragma once
// What the loop closer's plausibility gates measure (LoopCloserOptions::max_correction_ratio):
// how far the camera drove between two keyframes, over which odometry drifts by a few per cent at
// most, and how long tracking was lost before a map started after a loss.

#include <cstddef>

#include "sbaslam/map/map.h"

namespace sbaslam::loop {

// How far the camera went between keyframes `a` and `b` (either order), along the keyframes in
// the order they were made; a step between two maps has no length (their worlds differ).
// Keyframes with ids below `first_run_keyframe` came from a loaded map (map/map_file.h), which
// another drive made: from one of them to a keyframe of this run the path goes through the loaded
// keyframe nearest to where this run joined the map (its first keyframe), then along this run.
// Counting by id alone would add the loaded map's whole remaining drive and a jump to this run's
// start. 0: no map was loaded.
double driven_path_length(const map::Map& map, const map::KeyFrame& a, const map::KeyFrame& b,
                          std::size_t first_run_keyframe = 0);

// Tracking was lost between the last keyframe of this run made before `root` (a map started after
// the loss) and `root`: how long, and how fast the camera went over the keyframes before it. A
// loaded map's keyframes do not count: their stamps and speed are another drive's. A run from a
// loaded map whose first frame did not relocalise has no keyframe before `root`: its map started
// where no pose was known (`anchored` false), so a merge may move it by any amount.
struct Loss {
  double seconds = 0.0;
  double speed = 0.0;  // map units per second
  bool anchored = true;
};
Loss loss_before(const map::Map& map, const map::KeyFrame& root,
                 std::size_t first_run_keyframe = 0);

}  // namespace sbaslam::loop
