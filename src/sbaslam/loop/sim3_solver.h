#pragma once
// Geometric verification of a loop candidate: the similarity S12 between two keyframes from
// matched map points (ORB-SLAM's Sim3Solver). S12 maps points of keyframe 2's camera frame into
// keyframe 1's: p1 = s R p2 + t. A monocular map drifts in scale, so a loop needs all 7 DoF;
// stereo and RGB-D maps have metric scale and fix it to 1 (SE3).
//
// The refinement that follows a found S12 is optimize::refine_sim3 (optimize/sim3_refinement.h).

#include <cstdint>
#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/core/lie.h"
#include "sbaslam/optimize/sim3_refinement.h"

namespace sbaslam::loop {

// Declared in optimize/ so that the refinement does not depend on loop/.
using optimize::Sim3Correspondence;

// Closed-form (Umeyama 1991, Horn's least squares) similarity S12 minimising
// sum |p1 - S12 p2|^2; with fix_scale the scale is 1 (SE3). Throws sbaslam::Error when the sizes
// differ, there are fewer than 3 pairs, or the points are (nearly) collinear or coincident.
Sim3 align_points(const std::vector<Vec3>& p1, const std::vector<Vec3>& p2, bool fix_scale);

struct Sim3RansacOptions {
  double probability = 0.99;  // of drawing at least one all-inlier sample
  int min_inliers = 20;
  int max_iterations = 300;
  bool fix_scale = false;
  std::uint64_t seed = 0;
  double chi2 = 9.210;  // 99 % for 2 dof, times the keypoint's sigma2, in pixels^2
};

struct Sim3RansacResult {
  bool found = false;
  Sim3 S12;
  std::vector<char> inliers;  // one per correspondence
  int inlier_count = 0;
  int iterations = 0;  // samples drawn
};

// ORB-SLAM's Sim3Solver: minimal samples of 3 correspondences, each hypothesis scored by
// reprojecting p2 through S12 into camera 1 (against uv1) and p1 through S21 into camera 2
// (against uv2), both within chi2 * sigma2 pixels^2 and in front of the camera. The sample count
// is ORB-SLAM's, from an inlier ratio of min_inliers / n, lowered as better hypotheses are found
// and capped at max_iterations. The best hypothesis with >= min_inliers is refit on all its
// inliers (align_points) and re-scored; the refit is kept unless it has fewer inliers. Seeded
// std::mt19937_64: the same input and seed give the same result. found is false when fewer than
// max(3, min_inliers) correspondences are given or no hypothesis reaches min_inliers; S12 and
// the inliers are then those of the best hypothesis seen, for diagnostics only. Throws
// sbaslam::Error on invalid options.
Sim3RansacResult ransac_sim3(const std::vector<Sim3Correspondence>& c, const PinholeCamera& camera1,
                             const PinholeCamera& camera2, const Sim3RansacOptions& options);

}  // namespace sbaslam::loop
