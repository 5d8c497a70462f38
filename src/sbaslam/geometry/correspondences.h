#pragma once
// Point correspondences between two views as the two-view solvers read them: undistorted pixels
// and, per point, the inverse variance of its position (1 / sigma^2 of its pyramid level), so that
// residuals become chi-square values whatever octave a keypoint was detected at.

#include <vector>

#include "sbaslam/core/lie.h"

namespace sbaslam::geometry {

struct Correspondences {
  std::vector<Vec2> p1, p2;                        // pixels in view 1 and view 2
  std::vector<double> inv_sigma2_1, inv_sigma2_2;  // 1 / sigma^2 of each observation
  int size() const { return static_cast<int>(p1.size()); }
  void add(const Vec2& a, const Vec2& b, double inv_var_a = 1.0, double inv_var_b = 1.0) {
    p1.push_back(a);
    p2.push_back(b);
    inv_sigma2_1.push_back(inv_var_a);
    inv_sigma2_2.push_back(inv_var_b);
  }
};

// 95% quantiles of the chi-square distribution (ORB-SLAM's thresholds).
inline constexpr double kChi2OneDof = 3.841;
inline constexpr double kChi2TwoDof = 5.991;

// A model's support: ORB-SLAM's score sums (threshold - chi2) over the directions of the inliers,
// so a match counts more the better it fits.
struct ModelScore {
  double score = 0.0;
  std::vector<char> inliers;  // one flag per correspondence
  int inlier_count = 0;
};

// Hartley normalisation as ORB-SLAM's Normalize: centroid at the origin and unit mean absolute
// deviation per axis. `T` maps a pixel to its normalised point.
struct NormalizedPoints {
  std::vector<Vec2> points;
  Mat3 T = Mat3::Identity();
};
NormalizedPoints normalize_points(const std::vector<Vec2>& points);

}  // namespace sbaslam::geometry
