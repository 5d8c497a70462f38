#pragma once
// Monocular map initialisation from two views, as ORB-SLAM's TwoViewReconstruction: a homography
// and a fundamental matrix are estimated in parallel by RANSAC over the same seeded 8-point sets,
// the model is chosen by the ratio of their scores, its relative motion candidates are each
// triangulated, and the motion is accepted only when one candidate clearly wins with enough points
// and enough parallax. Every refusal says why, so that the caller can tell the user to "move the
// camera sideways" rather than silently building a bad map.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/geometry/motion_check.h"
#include "sbaslam/geometry/two_view_ransac.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::tracking {

enum class TwoViewModel { kNone, kHomography, kFundamental };

enum class TwoViewFailure {
  kNone,
  kTooFewMatches,       // fewer matches than options.min_matches
  kTooFewInliers,       // the chosen model is supported by fewer than min_triangulated matches
  kLowParallax,         // the best motion has too little parallax (includes pure rotation)
  kTooFewTriangulated,  // the best motion triangulates too few of the model's inliers
  kAmbiguous,           // two different motions explain the matches about equally well
};

// "homography", "fundamental", "none".
std::string_view to_string(TwoViewModel model);
// Short phrases for messages: "insufficient parallax", "ambiguous motion", ...
std::string_view to_string(TwoViewFailure failure);

struct TwoViewOptions {
  int ransac_iterations = 200;
  int min_matches = 100;          // ORB-SLAM's monocular tracker needs 100 initial matches
  int min_triangulated = 50;      // valid 3-D points (with parallax) of the accepted motion
  double min_parallax_deg = 1.0;  // of the parallax_rank-th most oblique point (see `check`)
  // The homography is chosen when R_H = S_H / (S_H + S_F) exceeds this: ORB-SLAM2's 0.40, not
  // ORB-SLAM3's 0.50. F's point-to-line errors have one degree of freedom against H's two, so
  // even on a perfect plane F scores higher once noise is present: measured R_H on a synthetic
  // floor is 0.47 at 0.5 px of noise and 0.39 at 1 px, against 0.15 for a non-planar scene with
  // the same motion. At 0.50 a plane would nearly always go to F (degenerate there).
  double homography_ratio = 0.40;
  // The best motion must support this fraction of the model's inliers (ORB-SLAM: 0.9).
  double min_supported_fraction = 0.9;
  // Clear winner: a rival motion must support fewer than this fraction of the best's points.
  // ORB-SLAM uses 0.75 for the 8 homography candidates and 0.7 for the 4 essential ones.
  double homography_rival_ratio = 0.75;
  double fundamental_rival_ratio = 0.7;
  // Candidates closer than both of these to the best one are the same motion (near-equal
  // singular values of a homography give near-duplicate candidates), not rivals.
  double same_motion_rotation_deg = 1.0;
  double same_motion_direction_deg = 5.0;
  geometry::MotionCheckOptions check;
  // Refine an essential-matrix motion by minimising the Sampson distance of its points (Ceres),
  // then triangulate again. ORB-SLAM leaves this to the initial bundle adjustment.
  bool refine = true;
  // When the fundamental matrix was chosen but fails, try the homography (ORB-SLAM does not).
  bool fallback_to_homography = true;
  bool parallel = true;  // H and F RANSAC on two threads; the result does not depend on it
};

// Throws sbaslam::Error naming the option for values the initialiser cannot work with.
void validate(const TwoViewOptions& options);

struct TwoViewResult {
  TwoViewFailure failure = TwoViewFailure::kTooFewMatches;
  std::string message;  // one line: why it refused, or what it accepted
  bool ok() const { return failure == TwoViewFailure::kNone; }

  TwoViewModel model = TwoViewModel::kNone;
  double score_h = 0.0, score_f = 0.0, ratio_h = 0.0;  // ratio_h = S_H / (S_H + S_F)
  int inliers_h = 0, inliers_f = 0;
  Mat3 H21 = Mat3::Zero(), F21 = Mat3::Zero();  // between undistorted pixels

  // The accepted motion (valid when ok()): X2 = R21 X1 + t21, |t21| = 1.
  Mat3 R21 = Mat3::Identity();
  Vec3 t21 = Vec3::Zero();
  SE3 T21() const { return SE3(SO3::from_matrix(R21), t21); }

  std::vector<Vec3> points;        // per match: the point in camera 1 (scale of |t21| = 1)
  std::vector<char> triangulated;  // per match: points[i] is a valid map point
  int triangulated_count = 0;
  double parallax_deg = 0.0;         // the parallax of the checked motion (see options.check)
  double median_parallax_deg = 0.0;  // median over its supporting matches
  int best_support = 0, rival_support = 0;  // supporting matches of the best and best rival
};

class TwoViewInitializer {
 public:
  // `levels` gives each keypoint's sigma^2 from its octave.
  TwoViewInitializer(const PinholeIntrinsics& k, feature::ScaleLevels levels,
                     TwoViewOptions options = {});

  // Keypoints are undistorted; match.query indexes keypoints1 and match.train keypoints2. The
  // seed fixes the RANSAC sets: the same inputs and seed give the same result. Matches pointing
  // outside the keypoints, or octaves outside `levels`, throw sbaslam::Error.
  TwoViewResult initialize(const std::vector<feature::OrbKeypoint>& keypoints1,
                           const std::vector<feature::OrbKeypoint>& keypoints2,
                           const std::vector<match::Match>& matches, std::uint64_t seed) const;

  const TwoViewOptions& options() const { return options_; }

 private:
  // Decomposes `fit`, checks its motions and accepts one or refuses, into `r`.
  void reconstruct(TwoViewModel model, const geometry::ModelFit& fit,
                   const geometry::Correspondences& c, TwoViewResult& r) const;

  PinholeIntrinsics k_;
  feature::ScaleLevels levels_;
  TwoViewOptions options_;
};

}  // namespace sbaslam::tracking
