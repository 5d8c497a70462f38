#include "sbaslam/sim/vehicle_path.h"

#include <algorithm>
#include <cmath>

#include "sbaslam/core/error.h"

namespace sbaslam::sim {
namespace {

double wrap_angle(double a) {
  return std::atan2(std::sin(a), std::cos(a));
}

}  // namespace

Route::Route(const std::vector<Vec2>& waypoints, double corner_radius, bool closed)
    : closed_(closed) {
  const std::size_t n = waypoints.size();
  if (n < 2) fail("route: needs at least two waypoints");
  // Tangent length cut from each segment end by the corner arcs.
  std::vector<double> cut(n, 0.0), turn(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!closed && (i == 0 || i + 1 == n)) continue;
    const Vec2 a = waypoints[(i + n - 1) % n], b = waypoints[i], c = waypoints[(i + 1) % n];
    const Vec2 d1 = (b - a).normalized(), d2 = (c - b).normalized();
    turn[i] = std::atan2(d1.x() * d2.y() - d1.y() * d2.x(), d1.dot(d2));
    cut[i] = corner_radius * std::tan(0.5 * std::abs(turn[i]));
  }
  const std::size_t segments = closed ? n : n - 1;
  double s = 0.0;
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2 a = waypoints[i], b = waypoints[(i + 1) % n];
    const Vec2 d = (b - a).normalized();
    const double heading = std::atan2(d.y(), d.x());
    const double straight = (b - a).norm() - cut[i] - cut[(i + 1) % n];
    if (straight < 0.0) fail("route: corners overlap between waypoints {} and {}", i, i + 1);
    pieces_.push_back({s, straight, a + d * cut[i], heading, 0.0});
    s += straight;
    const std::size_t j = (i + 1) % n;
    if (std::abs(turn[j]) > 1e-9) {
      const double k = (turn[j] > 0 ? 1.0 : -1.0) / corner_radius;
      const double arc = corner_radius * std::abs(turn[j]);
      pieces_.push_back({s, arc, b - d * cut[j], heading, k});
      s += arc;
    }
  }
  length_ = s;
}

RoutePoint Route::at(double s) const {
  if (closed_) {
    s = std::fmod(s, length_);
    if (s < 0.0) s += length_;
  } else {
    s = std::clamp(s, 0.0, length_);
  }
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s,
                             [](double value, const Piece& p) { return value < p.s0; });
  const Piece& p = *(it == pieces_.begin() ? it : it - 1);
  const double ds = s - p.s0;
  RoutePoint r;
  r.curvature = p.curvature;
  r.heading = wrap_angle(p.heading0 + p.curvature * ds);
  if (p.curvature == 0.0) {
    r.position = p.start + ds * Vec2(std::cos(p.heading0), std::sin(p.heading0));
  } else {
    const double k = p.curvature;
    r.position = p.start + Vec2((std::sin(p.heading0 + k * ds) - std::sin(p.heading0)) / k,
                                (std::cos(p.heading0) - std::cos(p.heading0 + k * ds)) / k);
  }
  return r;
}

RoutePoint Route::at(double s, double lateral_offset) const {
  RoutePoint r = at(s);
  r.position += lateral_offset * Vec2(std::sin(r.heading), -std::cos(r.heading));
  // The offset curve is concentric: its radius shrinks on the inside of a turn.
  if (r.curvature != 0.0) r.curvature = 1.0 / (1.0 / r.curvature + lateral_offset);
  return r;
}

DrivingSchedule::DrivingSchedule(const Route& route, const DrivingStyle& style, double start_s,
                                 double lateral_offset)
    : closed_(route.closed()) {
  period_length_ = closed_ ? route.length() : route.length() - start_s;
  const int count = std::max(2, static_cast<int>(period_length_ / step_) + 1);
  // v: speed in the lane; lane_step: lane length of the centre-line step after each sample.
  std::vector<double> v(static_cast<std::size_t>(count)), lane_step(v.size());
  for (int i = 0; i < count; ++i) {
    const double s = start_s + i * step_;
    const double k = route.at(s).curvature;
    const double stretch = 1.0 + k * lateral_offset;  // lane length per centre-line length
    lane_step[static_cast<std::size_t>(i)] = step_ * stretch;
    const double lane_curvature = std::abs(k) / stretch;
    // Traffic-like variation of the cruise speed along the route.
    const double cruise =
        style.cruise_speed * (1.0 + 0.1 * std::sin(s / 97.0) + 0.05 * std::sin(s / 23.0 + 1.0));
    v[static_cast<std::size_t>(i)] =
        lane_curvature > 1e-9
            ? std::min(cruise, std::sqrt(style.lateral_acceleration / lane_curvature))
            : cruise;
  }
  // Braking before and accelerating after the turns; run twice around a closed route so that the
  // profile is periodic.
  const int passes = closed_ ? 2 : 1;
  for (int pass = 0; pass < passes; ++pass) {
    for (int i = count - 1; i >= 0; --i) {
      const double next = (i + 1 < count) ? v[static_cast<std::size_t>(i + 1)]
                                          : (closed_ ? v[0] : v[static_cast<std::size_t>(i)]);
      auto& vi = v[static_cast<std::size_t>(i)];
      vi = std::min(vi, std::sqrt(next * next + 2.0 * style.deceleration *
                                                    lane_step[static_cast<std::size_t>(i)]));
    }
    for (int i = 0; i < count; ++i) {
      const double prev = i > 0 ? v[static_cast<std::size_t>(i - 1)]
                                : (closed_ ? v[static_cast<std::size_t>(count - 1)] : v[0]);
      auto& vi = v[static_cast<std::size_t>(i)];
      vi = std::min(vi, std::sqrt(prev * prev + 2.0 * style.acceleration *
                                                    lane_step[static_cast<std::size_t>(i)]));
    }
  }
  times_.assign(static_cast<std::size_t>(count), 0.0);
  for (int i = 1; i < count; ++i) {
    const double mean_speed =
        0.5 * (v[static_cast<std::size_t>(i)] + v[static_cast<std::size_t>(i - 1)]);
    times_[static_cast<std::size_t>(i)] = times_[static_cast<std::size_t>(i - 1)] +
                                          lane_step[static_cast<std::size_t>(i - 1)] / mean_speed;
  }
  // The lap closes with the step from the last sample back to the first.
  period_time_ = times_.back() + (closed_ ? lane_step.back() / v.back() : 0.0);
  if (closed_) period_length_ = count * step_;
}

double DrivingSchedule::distance_at(double t) const {
  double laps = 0.0;
  if (closed_) {
    laps = std::floor(t / period_time_);
    t -= laps * period_time_;
  } else {
    t = std::clamp(t, 0.0, times_.back());
  }
  auto it = std::upper_bound(times_.begin(), times_.end(), t);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - times_.begin()));
  if (i >= times_.size()) {
    // Between the last sample and the end of the lap.
    const double a = (t - times_.back()) / std::max(1e-12, period_time_ - times_.back());
    return laps * period_length_ + (times_.size() - 1 + a) * step_;
  }
  const double a = (t - times_[i - 1]) / (times_[i] - times_[i - 1]);
  return laps * period_length_ + (static_cast<double>(i - 1) + a) * step_;
}

double DrivingSchedule::speed_at(double t) const {
  const double dt = 0.01;
  return (distance_at(t + dt) - distance_at(std::max(0.0, t - dt))) / (t >= dt ? 2 * dt : dt + t);
}

double DrivingSchedule::time_for(double distance) const {
  double lo = 0.0, hi = 1.0;
  while (distance_at(hi) < distance && hi < 1e7) hi *= 2.0;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (distance_at(mid) < distance ? lo : hi) = mid;
  }
  return hi;
}

SE3 vehicle_camera_pose(const Route& route, const DrivingSchedule& schedule, double start_s,
                        double lateral_offset, double height, double t) {
  const double s = start_s + schedule.distance_at(t);
  const RoutePoint p = route.at(s, lateral_offset);
  const auto lane_speed = [&](double time) {
    const double h = 0.01;
    const auto lane_position = [&](double when) {
      return route.at(start_s + schedule.distance_at(std::max(0.0, when)), lateral_offset).position;
    };
    return (lane_position(time + h) - lane_position(time - h)).norm() /
           (time >= h ? 2 * h : h + time);
  };
  const double v = lane_speed(t);
  const double accel = (lane_speed(t + 0.1) - lane_speed(std::max(0.0, t - 0.1))) / 0.2;
  const double lateral_accel = v * v * p.curvature;
  // The body pitches nose-down when braking and rolls outwards in turns (soft suspension,
  // about 0.4 deg per m/s^2), over a slightly uneven road.
  const double pitch = 0.007 * accel + 0.004 * std::sin(s / 17.0) + 0.002 * std::sin(s / 5.3);
  const double roll = 0.007 * lateral_accel + 0.002 * std::sin(s / 11.0 + 0.7);
  const double bump = 0.01 * std::sin(s / 7.0);
  const Mat3 R_world_vehicle =
      (Eigen::AngleAxisd(p.heading, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
       Eigen::AngleAxisd(roll, Vec3::UnitX()))
          .toRotationMatrix();
  // Vehicle x forward, y left, z up; camera x right, y down, z forward.
  Mat3 R_vehicle_camera;
  R_vehicle_camera << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Vec3 position(p.position.x(), p.position.y(), height + bump);
  return SE3(SO3::from_matrix(R_world_vehicle * R_vehicle_camera), position);
}

}  // namespace sbaslam::sim
