#pragma once
// The two models of ORB-SLAM's initialiser, each estimated by normalised DLT from a minimal set
// and scored on every correspondence by symmetric transfer error:
//   homography  x2 ~ H21 x1          (planar scene or pure rotation),
//   fundamental x2^T F21 x1 = 0      (general scene with a baseline).
// The DLT functions take Hartley-normalised points (see normalize_points) and the indices of the
// sample; they return the model in the normalised frames, to be denormalised by the caller.

#include <vector>

#include "sbaslam/geometry/correspondences.h"

namespace sbaslam::geometry {

// Homography of normalised points by DLT (>= 4 indices), scaled to unit Frobenius norm.
Mat3 homography_dlt(const std::vector<Vec2>& p1, const std::vector<Vec2>& p2,
                    const std::vector<int>& indices);

// Fundamental matrix of normalised points by the 8-point algorithm (>= 8 indices), with the
// rank-2 constraint enforced.
Mat3 fundamental_8point(const std::vector<Vec2>& p1, const std::vector<Vec2>& p2,
                        const std::vector<int>& indices);

// ORB-SLAM's CheckHomography: transfer error in both images, chi2 = e^2 / sigma^2 of the image it
// is measured in; a match is an inlier when both directions are below `chi2_threshold`, and each
// direction below it adds (chi2_threshold - chi2) to the score, whether or not the other direction
// passes. A singular H scores nothing.
ModelScore score_homography(const Mat3& H21, const Correspondences& c,
                            double chi2_threshold = kChi2TwoDof);

// ORB-SLAM's CheckFundamental: squared distance to the epipolar line in both images. The gate is
// the 1-dof quantile; the score uses the 2-dof quantile so that H and F scores are comparable.
ModelScore score_fundamental(const Mat3& F21, const Correspondences& c,
                             double chi2_threshold = kChi2OneDof,
                             double score_threshold = kChi2TwoDof);

// Squared distance of x2 to the epipolar line F21 x1 (pixels^2); infinity for a null line.
double epipolar_distance2(const Mat3& F21, const Vec2& x1, const Vec2& x2);

}  // namespace sbaslam::geometry
