#pragma once
// The thin adapter between the map and saliency/stable_features: reads every good map point's
// keyframe observations into plain PointTracks, so the selection and the csv never see the map.
//
// Threads: runs on the caller's (the runner's) thread at the end of a run, after
// System::shutdown() stopped local mapping, inside System::read_map(), which holds the map lock.
// It reads map points (position, observations, badness) and keyframes (pose, measurements, rig);
// it writes nothing.

#include <functional>
#include <string>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/map/map.h"
#include "sbaslam/saliency/stable_features.h"

namespace sbaslam {

struct StableFeatureSources {
  // The image file name of the frame with this timestamp (as the dataset reader knows it).
  std::function<std::string(double timestamp)> image_of;
  // Pixel of the image SLAM saw -> pixel of the image file (e.g. EuRoC stereo's rectification
  // undone); identity when the two are the same.
  std::function<Vec2(const Vec2& pixel)> file_pixel;
};

// One track per good map point, with the reprojection error of each observation against the
// undistorted keypoint (left image only, also for stereo observations). Call with the map lock
// held.
std::vector<saliency::PointTrack> map_point_tracks(const map::Map& map,
                                                   const StableFeatureSources& sources);

}  // namespace sbaslam
