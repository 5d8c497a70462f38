#pragma once
// The indoor scene, EuRoC-like: a 10 m x 8 m x 3.5 m room with textured walls, posters, floor
// mats, ceiling tiles and furniture-like boxes, flown through by a MAV (or carried by hand) with
// 6-DoF motion, two fast rotations and a dark segment.
//
// Labels indoors use the nearest Cityscapes classes: walls and ceiling building (11), floor
// sidewalk (8, walkable flat ground), boxes and furniture fence (13, static construction).

#include <cstdint>

#include "sbaslam/sim/world.h"

namespace sbaslam::sim {

constexpr double kRoomHalfX = 5.0, kRoomHalfY = 4.0, kRoomHeight = 3.5;

World build_room_world(std::uint64_t seed, const std::vector<cv::Mat>& wall_photos);

// Pose of the MAV body (x forward, y left, z up) in the room at time t. The motion is a smooth
// closed curve with vibrations, the yaw sweeps the walls, and around t = 11 s and t = 27 s the
// body spins by a quarter turn within one second.
SE3 room_body_pose(double t, std::uint64_t seed);

// Light level of the room at time t: 1, except for a dark segment (down to 0.15) between 16 s and
// 21 s with one-second ramps.
double room_light_level(double t);

}  // namespace sbaslam::sim
