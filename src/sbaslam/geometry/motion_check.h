#pragma once
// ORB-SLAM's CheckRT: how well one candidate motion explains the inlier correspondences. Every
// inlier is triangulated; it supports the motion when it lies in front of both cameras (unless its
// rays are parallel, where depth means nothing) and reprojects within a chi-square gate in both
// images.

#include <vector>

#include "sbaslam/core/settings.h"
#include "sbaslam/geometry/correspondences.h"
#include "sbaslam/geometry/relative_pose.h"

namespace sbaslam::geometry {

struct MotionCheckOptions {
  double reprojection_chi2 = 4.0;  // squared pixels / sigma^2 (ORB-SLAM: 4 sigma^2)
  // Rays closer than this cosine (0.36 degrees) are "at infinity": their depth sign is not tested
  // and they do not count as triangulated, as in ORB-SLAM.
  double parallel_cos = 0.99998;
  // The reported parallax is that of the parallax_rank-th most oblique supporting point (ORB-SLAM
  // takes the 50th): "at least this many points see at least this parallax".
  int parallax_rank = 50;
};

struct MotionSupport {
  int good = 0;                      // supporting correspondences
  int triangulated = 0;              // supporting correspondences with parallax (valid 3-D points)
  double parallax_deg = 0.0;         // see MotionCheckOptions::parallax_rank
  double median_parallax_deg = 0.0;  // over the supporting correspondences
  std::vector<Vec3> points;          // per correspondence, in camera 1 (valid where `valid`)
  std::vector<char> valid;           // per correspondence: triangulated with parallax
};

MotionSupport check_motion(const RelativeMotion& motion, const Correspondences& c,
                           const std::vector<char>& inliers, const PinholeIntrinsics& k,
                           const MotionCheckOptions& options = {});

}  // namespace sbaslam::geometry
