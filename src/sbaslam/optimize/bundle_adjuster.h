#pragma once
// Bundle adjustment over keyframe poses and map points on Ceres, shared by local BA (local
// keyframes free, keyframes that also see the points fixed) and global BA (all keyframes, the
// first fixed). The map builds a BundleAdjustmentProblem, runs it and writes the result back, so
// this module knows nothing of the map's classes or locks.

#include <atomic>
#include <cmath>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

struct BaKeyframe {
  SE3 T_cw;
  bool fixed = false;
};

struct BaPoint {
  Vec3 position;
  bool fixed = false;
};

struct BaObservation {
  int keyframe = -1;  // index into BundleAdjustmentProblem::keyframes
  int point = -1;     // index into BundleAdjustmentProblem::points
  PixelObservation pixel;
};

struct BundleAdjustmentProblem {
  RectifiedCamera camera;
  std::vector<BaKeyframe> keyframes;
  std::vector<BaPoint> points;
  std::vector<BaObservation> observations;
};

struct BundleAdjusterOptions {
  int iterations = 5;
  // ORB-SLAM2's local BA: after the first pass, drop the chi-square outliers and refine again.
  // (ORB-SLAM3 v1.0 runs one robust pass of 10 iterations instead: tried, it lost on KITTI 06 and,
  // ended early, on city-dynamic; docs/RESULTS.md, "Session 9".)
  int refine_iterations = 10;
  // ORB-SLAM2 refines without the kernel: every inlier's chi-square is under the threshold, which
  // is the kernel's corner squared, so the kernel would not act. With Salient BA weights that no
  // longer holds: a weight w moves the corner to 1/sqrt(w) of its unit-weight error, and without
  // the kernel a weight of 257 pulls 257 times, where the robust pass let it pull about 16 times.
  // Under motion blur a few salient surfaces then steer the map (`room`: ATE 4.2x uniform; with
  // the kernel kept, 1.9x; docs/RESULTS.md, "Session 16"). For unit weights the two agree but for
  // inliers that cross the corner during the pass.
  bool refine_with_kernel = true;
  // Multiplies every observation's Salient BA weight. Scaling all weights by c moves the Huber
  // kernel's corner to 1/sqrt(c) of where it was, relative to the errors, and keeps the weights'
  // ratios: local and full BA take a wider corner than motion-only BA this way
  // (SaliencySettings::map_ba_max_weight says why).
  double weight_scale = 1.0;
  // Ceres ends a pass when an iteration changes the cost by less than this fraction.
  double function_tolerance = 1e-6;
  double huber_mono = std::sqrt(kChi2Mono);
  double huber_stereo = std::sqrt(kChi2Stereo);
  int num_threads = 1;
  // Above this many free keyframes the reduced camera system is solved sparsely.
  int dense_schur_max_keyframes = 60;
  // When set to true by another thread, the solve stops after the current iteration (ORB-SLAM's
  // local BA yields to a new keyframe this way).
  const std::atomic<bool>* abort = nullptr;
};

struct BundleAdjustmentReport {
  std::vector<bool> outlier;  // per observation: chi-square above threshold or point behind
  int outliers = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;   // Ceres iterations of both passes
  bool solved = false;  // false when there was nothing to optimise
};

// Optimises the free keyframes and points of `problem` in place.
BundleAdjustmentReport bundle_adjust(BundleAdjustmentProblem& problem,
                                     const BundleAdjusterOptions& options = {});

}  // namespace sbaslam::optimize
