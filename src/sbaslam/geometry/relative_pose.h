#pragma once
// Relative motion candidates from a two-view model, and linear triangulation.
//
// Conventions: R21, t21 map a point of camera 1 into camera 2 (X2 = R21 X1 + t21), as ORB-SLAM's
// initialiser. Translations are unit vectors: two views fix the motion only up to scale.

#include <optional>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"

namespace sbaslam::geometry {

struct RelativeMotion {
  Mat3 R21 = Mat3::Identity();
  Vec3 t21 = Vec3::Zero();     // unit norm
  Vec3 normal = Vec3::Zero();  // plane normal in camera 1 (homography candidates only)
};

struct HomographyDecomposition {
  std::vector<RelativeMotion> motions;  // the 8 Faugeras candidates (fewer when some coincide)
  // All three singular values of K^-1 H K equal: the homography of a pure rotation (or of a plane
  // at infinity) which fixes no translation at all.
  bool pure_rotation = false;
};

// Faugeras & Lustman's decomposition of a homography between undistorted pixels: the 4 solutions
// with d' = +d2 and the 4 with d' = -d2 of K^-1 H21 K = d R + t n^T. Two equal singular values
// (translation along the plane normal, or in the plane) make the formulas coincide pairwise; the
// duplicates are then dropped instead of refusing the motion as ORB-SLAM does.
HomographyDecomposition decompose_homography(const Mat3& H21, const PinholeIntrinsics& k);

// E = K^T F K.
Mat3 essential_from_fundamental(const Mat3& F21, const PinholeIntrinsics& k);

// The four (R, t) of an essential matrix: (R1, t), (R2, t), (R1, -t), (R2, -t).
std::vector<RelativeMotion> decompose_essential(const Mat3& E21);

// Linear (DLT) triangulation of normalised-plane observations x1 (camera 1) and x2 (camera 2);
// returns the point in camera 1, or nullopt when it is at infinity or not finite.
std::optional<Vec3> triangulate_linear(const Vec2& x1, const Vec2& x2, const Mat3& R21,
                                       const Vec3& t21);

// K of a pinhole camera.
Mat3 camera_matrix(const PinholeIntrinsics& k);

// Angles between rotations and between directions, in degrees.
double rotation_angle_deg(const Mat3& Ra, const Mat3& Rb);
double direction_angle_deg(const Vec3& a, const Vec3& b);

}  // namespace sbaslam::geometry
