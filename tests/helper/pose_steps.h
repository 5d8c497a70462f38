#pragma once
// Poses one step h either side of `pose` along tangent direction k of the pose manifold, for
// central-difference checks of analytic Jacobians.

#include <utility>

#include "sbaslam/optimize/pose_parameter.h"

namespace sbaslam::test {

inline std::pair<optimize::PoseParameters, optimize::PoseParameters> tangent_steps(
    const optimize::PoseParameters& pose, int k, double h) {
  const optimize::PoseManifold manifold;
  double delta[6] = {0, 0, 0, 0, 0, 0};
  optimize::PoseParameters plus, minus;
  delta[k] = h;
  manifold.Plus(pose.data(), delta, plus.data());
  delta[k] = -h;
  manifold.Plus(pose.data(), delta, minus.data());
  return {plus, minus};
}

}  // namespace sbaslam::test
