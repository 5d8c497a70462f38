#pragma once
// Conversion between SE3 and the 7-double parameter block [qx qy qz qw tx ty tz] that Ceres
// optimises, with the quaternion updated on its manifold and the translation in R^3.

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include <array>
#include <memory>

#include "sbaslam/core/lie.h"

namespace sbaslam::optimize {

using PoseParameters = std::array<double, 7>;

inline PoseParameters to_parameters(const SE3& T) {
  const Quat& q = T.quaternion();
  const Vec3& t = T.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

inline SE3 from_parameters(const PoseParameters& p) {
  return SE3(Quat(p[3], p[0], p[1], p[2]), Vec3(p[4], p[5], p[6]));
}

using PoseManifold =
    ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

inline std::unique_ptr<ceres::Manifold> make_pose_manifold() {
  return std::make_unique<PoseManifold>(ceres::EigenQuaternionManifold(),
                                        ceres::EuclideanManifold<3>());
}

}  // namespace sbaslam::optimize
