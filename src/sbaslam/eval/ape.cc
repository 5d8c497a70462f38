#include "sbaslam/eval/ape.h"

#include "sbaslam/core/error.h"

namespace sbaslam::eval {

std::vector<double> absolute_pose_errors(const PoseSeries& reference, const PoseSeries& estimate,
                                         PoseRelation relation) {
  if (reference.size() != estimate.size())
    fail("APE needs paired poses ({} reference, {} estimate)", reference.size(), estimate.size());
  std::vector<double> errors;
  errors.reserve(reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Mat4& Q = reference.poses[i];
    const Mat4& P = estimate.poses[i];
    if (relation == PoseRelation::kTransPart)
      errors.push_back((P.topRightCorner<3, 1>() - Q.topRightCorner<3, 1>()).norm());
    else
      errors.push_back(pose_error(relative_se3(Q, P), relation));
  }
  return errors;
}

}  // namespace sbaslam::eval
