#pragma once
// Pose algebra on raw 4x4 matrices as evo does it, and evo's pose relations (the scalar error
// extracted from an error pose). Raw matrices matter: KITTI rotations are not exactly
// orthonormal, and re-projecting them onto SO(3) would change the RPE numbers.

#include <string>

#include "sbaslam/core/lie.h"

namespace sbaslam::eval {

enum class PoseRelation { kTransPart, kAngleDeg, kAngleRad, kFull };

// "trans_part", "angle_deg", "angle_rad" or "full"; anything else throws sbaslam::Error.
PoseRelation parse_pose_relation(const std::string& name);
std::string pose_relation_name(PoseRelation relation);
// Human-readable, as in evo's titles: "translation part (m)".
std::string pose_relation_description(PoseRelation relation);

// evo's se3_inverse: [R^T | -R^T t], which is not a general inverse for non-orthonormal R.
Mat4 se3_inverse(const Mat4& T);
// evo's relative_se3(a, b) = se3_inverse(a) * b.
Mat4 relative_se3(const Mat4& a, const Mat4& b);

// Rotation angle in [0, pi] as scipy's Rotation.from_matrix(R).magnitude(): a quaternion from
// the raw matrix by the largest of diag/trace (no re-orthonormalisation), then
// 2 atan2(|v|, |w|).
double rotation_angle(const Mat3& R);

// The scalar error of an error pose E (identity = no error).
double pose_error(const Mat4& E, PoseRelation relation);

}  // namespace sbaslam::eval
