#include "sbaslam/tracking/pose_prior.h"

#include <algorithm>

namespace sbaslam::tracking {

bool within(const PosePrior& prior, const SE3& T_cw) {
  return (T_cw.inverse().translation() - prior.centre).norm() <= prior.radius;
}

void keep_nearest(std::vector<map::KeyFrame*>& candidates, const PosePrior& prior,
                  std::size_t count) {
  auto distance = [&prior](const map::KeyFrame* kf) {
    return (kf->T_wc().translation() - prior.centre).squaredNorm();
  };
  std::stable_sort(candidates.begin(), candidates.end(),
                   [&distance](const map::KeyFrame* a, const map::KeyFrame* b) {
                     return distance(a) < distance(b);
                   });
  if (candidates.size() > count) candidates.resize(count);
}

}  // namespace sbaslam::tracking
