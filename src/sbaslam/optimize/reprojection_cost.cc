#include "sbaslam/optimize/reprojection_cost.h"

namespace sbaslam::optimize {

ReprojectionCheck check_reprojection(const RectifiedCamera& cam, const double* pose_qt,
                                     const double* point, const PixelObservation& obs) {
  double p[3];
  transform_to_camera(pose_qt, point, p);
  ReprojectionCheck check;
  check.in_front = p[2] > 0.0;
  if (!check.in_front) return check;
  const double u = cam.fx * p[0] / p[2] + cam.cx;
  const double v = cam.fy * p[1] / p[2] + cam.cy;
  const double du = obs.u - u;
  const double dv = obs.v - v;
  double sq = du * du + dv * dv;
  if (obs.is_stereo()) {
    const double dr = obs.u_right - (u - cam.bf / p[2]);
    sq += dr * dr;
  }
  check.chi2 = sq * obs.inv_sigma2;
  return check;
}

}  // namespace sbaslam::optimize
