#pragma once
// Absolute pose error (evo's APE) between paired poses.

#include <vector>

#include "sbaslam/eval/association.h"
#include "sbaslam/eval/pose_relation.h"

namespace sbaslam::eval {

// One error per pose pair. trans_part is ||t_P - t_Q|| (as evo, from positions only); the other
// relations use E = se3_inverse(Q_i) P_i.
std::vector<double> absolute_pose_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                         PoseRelation relation);

}  // namespace sbaslam::eval
