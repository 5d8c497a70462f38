#pragma once
// ORB descriptor matching as ORB-SLAM's ORBmatcher: matching by projection inside a radius that
// grows with the predicted octave's scale, the nearest / second-nearest ratio test, a rotation
// consistency histogram, and brute force between two frames with an optional cross-check.

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/match/feature_grid.h"

namespace sbaslam::match {

inline constexpr int kThresholdHigh = 100;  // ORB-SLAM's TH_HIGH
inline constexpr int kThresholdLow = 50;    // ORB-SLAM's TH_LOW

struct Match {
  int query = -1;  // index into the query set (projected points, or the first frame)
  int train = -1;  // keypoint index in the searched frame
  int distance = 0;
};

// What the matcher reads of the frame it searches.
struct FrameView {
  const std::vector<feature::OrbKeypoint>& keypoints;  // undistorted, as indexed by `grid`
  const cv::Mat& descriptors;                          // N x 32, CV_8U
  const FeatureGrid& grid;
  const feature::ScaleLevels& levels;
  const std::vector<float>* u_right = nullptr;  // stereo: right column per keypoint, -1 if none
};

// Keeps the matches whose rotation (angle in the searched frame minus angle in the reference)
// falls in the three most populated bins of a histogram over 360 degrees. As ORB-SLAM, the second
// and third bins count only if they hold at least a tenth of the first.
class RotationConsistency {
 public:
  explicit RotationConsistency(int bins = 30);
  void add(int match_id, float reference_angle_deg, float angle_deg);
  // Sorted ids of the matches outside the kept bins.
  std::vector<int> inconsistent() const;

 private:
  std::vector<std::vector<int>> bins_;
};

// A point predicted in the searched frame (a map point, or a keypoint of another frame).
struct ProjectedPoint {
  float u = 0.0f, v = 0.0f;  // undistorted pixel
  float u_right = -1.0f;     // predicted right column (stereo), < 0 when unknown
  int level = 0;             // predicted (or observed) octave
  const std::uint8_t* descriptor = nullptr;
  float angle = -1.0f;         // reference keypoint angle, for the rotation check
  float radius_factor = 1.0f;  // e.g. ORB-SLAM's viewing-angle factor (1 or 1.2)
};

struct ProjectionOptions {
  float radius = 1.0f;  // pixels at level 0; the window is radius * radius_factor * scale[level]
  int levels_below = 1, levels_above = 0;  // octaves searched: [level - below, level + above]
  float nn_ratio = 0.8f;                   // best must be < ratio * second best
  bool ratio_same_level_only = true;       // ORB-SLAM applies the ratio only within one octave
  int max_distance = kThresholdHigh;
  bool check_orientation = false;
  int rotation_bins = 30;
};

// One match per projected point at most, and one per frame keypoint: when two points pick the
// same keypoint, the closer descriptor wins. Keypoints with `taken[i]` set are skipped.
std::vector<Match> match_by_projection(const std::vector<ProjectedPoint>& points,
                                       const FrameView& frame, const ProjectionOptions& options,
                                       const std::vector<char>* taken = nullptr);

// ORB-SLAM's SearchForInitialization: level-0 keypoints of the first frame looked up around the
// same pixel in the second, TH_LOW, ratio 0.9 and the rotation check by default.
struct WindowOptions {
  float window = 100.0f;
  float nn_ratio = 0.9f;
  int max_distance = kThresholdLow;
  bool check_orientation = true;
  bool level0_only = true;
};
std::vector<Match> match_in_window(const std::vector<feature::OrbKeypoint>& first_keypoints,
                                   const cv::Mat& first_descriptors, const FrameView& second,
                                   const WindowOptions& options = {});

struct BruteForceOptions {
  int max_distance = kThresholdHigh;
  float nn_ratio = 1.0f;  // 1 disables the ratio test
  bool cross_check = true;
};
// The rows of `descriptors` listed in `rows`, in that order: a query set for match_brute_force.
cv::Mat descriptor_rows(const cv::Mat& descriptors, const std::vector<std::size_t>& rows);

// Every query descriptor against every train descriptor.
std::vector<Match> match_brute_force(const cv::Mat& query, const cv::Mat& train,
                                     const BruteForceOptions& options = {});

}  // namespace sbaslam::match
