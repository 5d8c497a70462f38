#pragma once
// Non-linear refinement of a relative motion on its inlier correspondences: R21 and the unit
// translation direction minimise the Sampson distance (the first-order geometric distance of a
// correspondence to the epipolar constraint, in pixels), weighted by each point's sigma. A linear
// model from RANSAC fits the noise of its samples; this brings the motion close to the maximum
// likelihood estimate before any bundle adjustment.

#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/geometry/correspondences.h"
#include "sbaslam/geometry/relative_pose.h"

namespace sbaslam::geometry {

struct RefinementOptions {
  // Each round re-selects the inliers by their Sampson distance to the current motion, then
  // solves. Selecting by the RANSAC model's own gate would bias the fit towards that model.
  int rounds = 3;
  double inlier_chi2 = 3.841;  // Sampson distance^2 / sigma^2, one degree of freedom
  int max_iterations = 50;
  double huber_px = 1.96;  // sqrt(3.841): robust beyond the 95% gate of one degree of freedom
};

// Sampson distance in pixels of (p1, p2) under the motion.
double sampson_distance(const RelativeMotion& motion, const PinholeIntrinsics& k, const Vec2& p1,
                        const Vec2& p2);

// Refines over the correspondences within the gate; returns the last good motion when fewer than
// 8 are within it or the solver fails. Deterministic (single thread).
RelativeMotion refine_motion(const RelativeMotion& motion, const Correspondences& c,
                             const PinholeIntrinsics& k, const RefinementOptions& options = {});

struct PlaneRefinementOptions {
  int rounds = 3;              // each re-selects the correspondences within the gate
  double inlier_chi2 = 5.991;  // per direction: transfer error^2 / sigma^2, two degrees of freedom
  int max_iterations = 50;
  double huber = 2.45;  // sqrt(5.991)
};

// Refines a homography candidate (`motion` with its plane normal, from decompose_homography of
// H21 between pixels) by minimising the symmetric transfer error of H = R + (t / d) n^T over R,
// t / d and n. The 8-point DLT homography fits its sample's noise; on a plane the epipolar
// constraint cannot refine the motion (every F through the plane fits), the homography can.
// Returns `motion` when fewer than 8 correspondences are within the gate or the solver fails.
RelativeMotion refine_plane_motion(const RelativeMotion& motion, const Mat3& H21,
                                   const Correspondences& c, const PinholeIntrinsics& k,
                                   const PlaneRefinementOptions& options = {});

}  // namespace sbaslam::geometry
