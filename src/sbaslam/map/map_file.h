#pragma once
// Map files: a run's map saved at its end and loaded by a later run, to localise in it or to map
// on from it (ORB-SLAM3's System.SaveAtlasToFile and System.LoadAtlasFromFile). The file keeps
// every live keyframe (pose, measurements with their Salient BA weights, covisibility weights,
// spanning tree, loop edges, map id) and every live map point (position, descriptor, viewing
// range, observations, tracking statistics), so a loaded map is the saved one: saving it again
// gives the same bytes. Bad keyframes and points are left out; so are the frames' trajectory
// (the run's trajectory files hold it) and the bags of words (loop closing computes them again).
//
// The format is binary, in the byte order of the machine that wrote it (a marker word rejects a
// file of the other order). ORB-SLAM3's own atlas files (boost archives) are not read.

#include <cstddef>
#include <string>

#include "sbaslam/map/map.h"

namespace sbaslam::map {

struct MapFileSummary {
  std::size_t keyframes = 0;
  std::size_t map_points = 0;
  std::size_t maps = 0;  // distinct map ids among the keyframes
  std::size_t max_frame_id = 0;
  std::size_t biggest_map_id = 0;  // the map with the most keyframes (the lowest id on a tie)
};

// Writes the live part of `map`, taken with the rig it was made with. Call with the map lock held
// or with no other thread running. Throws sbaslam::Error naming the file when it cannot write.
MapFileSummary save_map(const Map& map, const CameraRig& rig, const std::string& path);

// Fills `map`, which must be empty, from a file saved with the same camera: `rig` is given to the
// keyframes and must match the file's (image size, intrinsics, baseline, sensor, pyramid).
// Throws sbaslam::Error naming the file for a missing, truncated, corrupt or foreign file and
// for a camera that does not match.
MapFileSummary load_map(const std::string& path, const CameraRig& rig, Map& map);

}  // namespace sbaslam::map
