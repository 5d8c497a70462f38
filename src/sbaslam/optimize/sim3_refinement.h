#pragma once
// ORB-SLAM's Optimizer::OptimizeSim3: the nonlinear refinement of the similarity S12 between two
// keyframes (it maps points of keyframe 2's camera frame into keyframe 1's) that a loop candidate's
// RANSAC (loop/sim3_solver.h) found. Each matched pair of map points contributes two reprojection
// errors, one in each image, so that neither keyframe's depth errors dominate: the 3D points stay
// fixed, only S12 moves.
//
// The correspondence type lives here rather than in loop/ so that optimize/ does not depend on
// loop/; loop/sim3_solver.h re-exports it as loop::Sim3Correspondence.

#include <vector>

#include "sbaslam/core/camera.h"
#include "sbaslam/core/lie.h"

namespace sbaslam::optimize {

// One 3D-3D correspondence between keyframe 1 and keyframe 2 (a map point of each, matched by
// descriptor).
struct Sim3Correspondence {
  Vec3 p1_c;  // point of KF1's map point in KF1's camera frame
  Vec3 p2_c;  // point of KF2's map point in KF2's camera frame
  Vec2 uv1;   // the keypoint in KF1 (undistorted pixel) the pair was matched at
  Vec2 uv2;   // the keypoint in KF2
  double sigma2_1 = 1.0, sigma2_2 = 1.0;  // level variances of those keypoints
};

struct Sim3RefinementOptions {
  double huber_chi2 = 10.0;  // Huber threshold and outlier gate, on e^T Sigma^-1 e (2 dof)
  int iterations_first = 5;
  int iterations_second = 5;
  bool fix_scale = false;  // stereo / RGB-D: SE3 only, the scale stays at the initial value
};

struct Sim3RefinementResult {
  Sim3 S12;
  std::vector<char> inliers;  // one per correspondence, 1 for an inlier of the final round
  int inlier_count = 0;
};

// Refines S12 from `initial`. Per pair: S12 p2_c projected in camera 1 against uv1 and S12^-1 p1_c
// projected in camera 2 against uv2, each scaled by 1/sigma and under its own Huber kernel
// (delta sqrt(huber_chi2)). After the first round, pairs with either chi2 above huber_chi2 or a
// point behind either camera are dropped; the second round runs on the others, and the result's
// inliers are the pairs that pass the same test after it. With fix_scale the returned scale is
// exactly initial.scale() (1 for the SE3 of a stereo loop). Throws sbaslam::Error on invalid
// options.
Sim3RefinementResult refine_sim3(const std::vector<Sim3Correspondence>& c, const Sim3& initial,
                                 const PinholeCamera& camera1, const PinholeCamera& camera2,
                                 const Sim3RefinementOptions& options);

}  // namespace sbaslam::optimize
