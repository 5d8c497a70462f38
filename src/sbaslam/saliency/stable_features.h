#pragma once
// Self-supervised saliency labels: the features a SLAM run kept as long-lived, low-error map
// points. Where the paper's semantic gaze needs semantic labels to drop features on moving
// objects, a SLAM run drops them by itself (they fail the motion model, are culled or never
// gather enough keyframes). This file only selects and stores them; it knows nothing about the
// map (the runner fills the plain structs below under the map lock) and nothing about datasets.
//
// stable_features.csv, one row per (keyframe, observation) of a stable point, ordered by keyframe
// timestamp, then point id:
//   timestamp,image,x,y,octave,point_id,observations,mean_error_px
// timestamp: the keyframe's, seconds; image: the keyframe's image file name as the dataset reader
// knows it; x, y: the keypoint's level-0 position in that image file (raw pixels: distorted, and
// unrectified for EuRoC stereo); octave: its pyramid level; observations: keyframes observing the
// point; mean_error_px: the point's mean reprojection error over those observations, in pixels.

#include <cstddef>
#include <string>
#include <vector>

namespace sbaslam::saliency {

// One keyframe's observation of a map point.
struct PointObservation {
  double timestamp = 0.0;    // of the keyframe
  std::string image;         // the keyframe's image file name
  float x = 0.0f, y = 0.0f;  // level-0 keypoint position in the image file (raw pixels)
  int octave = 0;
  double error_px = 0.0;     // reprojection error (undistorted pixels); infinite behind the camera
  double level_sigma = 1.0;  // the keypoint's level scale (ORB-SLAM's sigma, 1 at level 0)
};

// A map point that is not bad, with all its keyframe observations.
struct PointTrack {
  std::size_t point_id = 0;
  std::vector<PointObservation> observations;
};

struct StabilityGate {
  int min_observations = 4;  // keyframes observing the point
  // Gate on the squared mean normalised error (mean of error_px / level_sigma over the
  // observations, squared): ORB-SLAM's 2-dof chi-square at 95 %.
  double max_chi2 = 5.991;
};

// One row of stable_features.csv.
struct StableFeature {
  double timestamp = 0.0;
  std::string image;
  float x = 0.0f, y = 0.0f;
  int octave = 0;
  std::size_t point_id = 0;
  int observations = 0;
  double mean_error_px = 0.0;
};

// Whether a track passes the gate (enough keyframes, small mean normalised error).
bool is_stable(const PointTrack& track, const StabilityGate& gate);

// The rows for every stable track, ordered by (timestamp, point_id).
std::vector<StableFeature> select_stable_features(const std::vector<PointTrack>& tracks,
                                                  const StabilityGate& gate);

// Writes the csv (header included); throws sbaslam::Error naming the file when it cannot.
void write_stable_features_csv(const std::string& path, const std::vector<StableFeature>& rows);

// Reads a csv written by write_stable_features_csv. A missing file, a wrong header or a bad row
// is a one-line sbaslam::Error naming the file (and the line).
std::vector<StableFeature> read_stable_features_csv(const std::string& path);

}  // namespace sbaslam::saliency
