#pragma once
// A road vehicle's motion: a planar route through waypoints with circular corners, a speed
// profile bounded by lateral and longitudinal acceleration, and the resulting 6-DoF poses with
// the small pitch and roll a car body shows when it brakes, accelerates and turns.

#include <vector>

#include "sbaslam/core/lie.h"

namespace sbaslam::sim {

// Pose of a point on the route: position on the ground plane and heading (radians from +x).
struct RoutePoint {
  Vec2 position = Vec2::Zero();
  double heading = 0.0;
  double curvature = 0.0;  // 1/m, positive turning left
};

class Route {
 public:
  // Straight segments through the waypoints joined by arcs of corner_radius. A closed route
  // also turns at the first waypoint and its arc length wraps around.
  Route(const std::vector<Vec2>& waypoints, double corner_radius, bool closed);

  double length() const { return length_; }
  bool closed() const { return closed_; }
  // s is wrapped for a closed route and clamped for an open one.
  RoutePoint at(double s) const;
  // Point offset sideways from the centre line (positive to the right of the direction).
  RoutePoint at(double s, double lateral_offset) const;

 private:
  struct Piece {
    double s0, length;
    Vec2 start;
    double heading0;
    double curvature;
  };
  std::vector<Piece> pieces_;
  double length_ = 0.0;
  bool closed_ = false;
};

struct DrivingStyle {
  double cruise_speed = 10.0;         // m/s on straights, modulated by +-15% along the route
  double lateral_acceleration = 2.0;  // m/s^2 allowed in turns
  double acceleration = 1.2;          // m/s^2
  double deceleration = 2.0;          // m/s^2
};

// Arc length travelled as a function of time along a route, from the speed profile. The profile
// is the vehicle's own, in the lane at `lateral_offset`: on the outside of a corner the lane is
// longer than the centre line, and a schedule made for the centre line would make the vehicle
// jump in speed (by 30% in the city's corners) as it enters one.
class DrivingSchedule {
 public:
  DrivingSchedule(const Route& route, const DrivingStyle& style, double start_s,
                  double lateral_offset = 0.0);

  // Arc length (unwrapped, from start_s) at time t >= 0; continues around a closed route.
  double distance_at(double t) const;
  // Rate of change of distance_at (centre-line arc length per second).
  double speed_at(double t) const;
  // Time to drive `distance` metres from the start.
  double time_for(double distance) const;

 private:
  double period_time_ = 0.0;  // one lap (closed) or the whole route (open)
  double period_length_ = 0.0;
  std::vector<double> times_;  // at samples every step_ metres from start_s
  // Fine enough that the speed interpolated across a corner boundary stays smooth.
  double step_ = 0.05;
  bool closed_ = false;
};

// Camera pose of a car-mounted camera at `height` above the road, following the schedule in the
// lane at `lateral_offset`, with body pitch and roll from the accelerations.
// The camera looks forward: x right, y down, z along the driving direction.
SE3 vehicle_camera_pose(const Route& route, const DrivingSchedule& schedule, double start_s,
                        double lateral_offset, double height, double t);

}  // namespace sbaslam::sim
