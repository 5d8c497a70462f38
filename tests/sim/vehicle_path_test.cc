#include "sbaslam/sim/vehicle_path.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sbaslam/sim/city_scene.h"

namespace sbaslam::sim {
namespace {

// The ego camera of the city scenes, sampled at KITTI's 10 Hz over a whole lap.
std::vector<SE3> city_camera_poses(double lateral_offset, int frames) {
  const Route route = city_loop_route();
  const DrivingSchedule schedule(route, DrivingStyle{}, 0.0, lateral_offset);
  std::vector<SE3> poses;
  for (int i = 0; i < frames; ++i)
    poses.push_back(
        vehicle_camera_pose(route, schedule, 0.0, lateral_offset, kCityCameraHeight, 0.1 * i));
  return poses;
}

TEST(DrivingSchedule, LaneSpeedChangesNoFasterThanTheStyleAllows) {
  // Entering a corner on its outside must not make the car jump in speed: the distance driven per
  // frame may change by at most (max acceleration) * dt^2 = 2.0 m/s^2 * 0.01 s^2 from frame to
  // frame (plus a little for the sampling of the profile).
  const std::vector<SE3> poses = city_camera_poses(kCityEgoLane, 1700);
  double worst = 0.0;
  std::size_t worst_frame = 0;
  for (std::size_t i = 2; i < poses.size(); ++i) {
    const double step = (poses[i].translation() - poses[i - 1].translation()).norm();
    const double previous = (poses[i - 1].translation() - poses[i - 2].translation()).norm();
    if (std::abs(step - previous) > worst) {
      worst = std::abs(step - previous);
      worst_frame = i;
    }
  }
  EXPECT_LT(worst, 0.025) << "at frame " << worst_frame;
}

TEST(DrivingSchedule, LateralAccelerationInTheLaneStaysBounded) {
  const Route route = city_loop_route();
  const DrivingStyle style;
  const DrivingSchedule schedule(route, style, 0.0, kCityEgoLane);
  double worst = 0.0;
  const auto lane_position = [&](double t) {
    return route.at(schedule.distance_at(t), kCityEgoLane).position;
  };
  for (double t = 0.05; t < 150.0; t += 0.05) {
    const double lane_speed = (lane_position(t + 0.05) - lane_position(t - 0.05)).norm() / 0.1;
    const double lane_curvature =
        std::abs(route.at(schedule.distance_at(t), kCityEgoLane).curvature);
    worst = std::max(worst, lane_speed * lane_speed * lane_curvature);
  }
  EXPECT_GT(worst, 0.5 * style.lateral_acceleration);  // the route does have corners
  // Speed is measured over 0.1 s, which straddles a corner's start or end for a moment.
  EXPECT_LT(worst, 1.1 * style.lateral_acceleration);
}

}  // namespace
}  // namespace sbaslam::sim
