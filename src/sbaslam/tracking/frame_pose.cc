#include "sbaslam/tracking/frame_pose.h"

namespace sbaslam::tracking {

int optimize_frame_pose(Frame& frame, const map::CameraRig& rig) {
  std::vector<Vec3> points;
  std::vector<optimize::PixelObservation> observations;
  std::vector<std::size_t> keypoint_of;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    const map::MapPoint* mp = frame.map_points[i];
    if (!mp || mp->is_bad()) continue;
    points.push_back(mp->position());
    observations.push_back(optimize::observation_of(frame.m(), i, rig));
    keypoint_of.push_back(i);
  }
  const optimize::PoseOptimizer optimizer(optimize::rectified_camera(rig));
  SE3 T_cw = frame.T_cw;
  const optimize::PoseOptimizationResult result = optimizer.optimize(T_cw, points, observations);
  frame.set_pose(T_cw);
  for (std::size_t j = 0; j < keypoint_of.size(); ++j)
    frame.outlier[keypoint_of[j]] = result.outlier[j] ? 1 : 0;
  return result.inliers;
}

}  // namespace sbaslam::tracking
