#include "sbaslam/eval/pose_relation.h"

#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::eval {

PoseRelation parse_pose_relation(const std::string& name) {
  if (name == "trans_part") return PoseRelation::kTransPart;
  if (name == "angle_deg") return PoseRelation::kAngleDeg;
  if (name == "angle_rad") return PoseRelation::kAngleRad;
  if (name == "full") return PoseRelation::kFull;
  fail("unknown pose relation '{}' (expected trans_part, angle_deg, angle_rad or full)", name);
}

std::string pose_relation_name(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTransPart:
      return "trans_part";
    case PoseRelation::kAngleDeg:
      return "angle_deg";
    case PoseRelation::kAngleRad:
      return "angle_rad";
    case PoseRelation::kFull:
      return "full";
  }
  return "unknown";
}

std::string pose_relation_description(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTransPart:
      return "translation part (m)";
    case PoseRelation::kAngleDeg:
      return "rotation angle in degrees (deg)";
    case PoseRelation::kAngleRad:
      return "rotation angle in radians (rad)";
    case PoseRelation::kFull:
      return "full transformation (unit-less)";
  }
  return "unknown";
}

Mat4 se3_inverse(const Mat4& T) {
  const Mat3 R_inv = T.topLeftCorner<3, 3>().transpose();
  Mat4 inv = Mat4::Identity();
  inv.topLeftCorner<3, 3>() = R_inv;
  inv.topRightCorner<3, 1>() = -R_inv * T.topRightCorner<3, 1>();
  return inv;
}

Mat4 relative_se3(const Mat4& a, const Mat4& b) {
  return se3_inverse(a) * b;
}

double rotation_angle(const Mat3& R) {
  // Markley / Shepperd: build the quaternion component that is largest in magnitude first.
  const double trace = R(0, 0) + R(1, 1) + R(2, 2);
  int choice = 3;
  double best = trace;
  for (int i = 0; i < 3; ++i) {
    if (R(i, i) > best) {
      best = R(i, i);
      choice = i;
    }
  }
  double v[3];
  double w;
  if (choice != 3) {
    const int i = choice;
    const int j = (i + 1) % 3;
    const int k = (j + 1) % 3;
    v[i] = 1.0 - trace + 2.0 * R(i, i);
    v[j] = R(j, i) + R(i, j);
    v[k] = R(k, i) + R(i, k);
    w = R(k, j) - R(j, k);
  } else {
    v[0] = R(2, 1) - R(1, 2);
    v[1] = R(0, 2) - R(2, 0);
    v[2] = R(1, 0) - R(0, 1);
    w = 1.0 + trace;
  }
  const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + w * w);
  const double vector_norm =
      std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / norm;  // |v| of the unit quaternion
  return 2.0 * std::atan2(vector_norm, std::abs(w / norm));
}

double pose_error(const Mat4& E, PoseRelation relation) {
  constexpr double kRadToDeg = 180.0 / M_PI;
  switch (relation) {
    case PoseRelation::kTransPart:
      return E.topRightCorner<3, 1>().norm();
    case PoseRelation::kAngleDeg:
      return rotation_angle(E.topLeftCorner<3, 3>()) * kRadToDeg;
    case PoseRelation::kAngleRad:
      return rotation_angle(E.topLeftCorner<3, 3>());
    case PoseRelation::kFull:
      return (E - Mat4::Identity()).norm();
  }
  return 0.0;
}

}  // namespace sbaslam::eval
