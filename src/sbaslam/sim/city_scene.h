#pragma once
// The synthetic city: a grid of streets (four lanes, parking lanes, raised sidewalks) lined with
// buildings, shop signs, street lamps, trees, traffic signs, traffic lights and parked cars, plus
// an overpass and a tram track; and the traffic that drives and walks through it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sbaslam/sim/vehicle_path.h"
#include "sbaslam/sim/world.h"

namespace sbaslam::sim {

// Street plan: the street centre lines x = c and y = c for c in kCityStreetLines, with 60 m of
// street beyond the outer crossings.
constexpr double kCityStreetLines[] = {0.0, 120.0, 240.0};
constexpr double kCityLaneWidth = 3.2;          // two lanes per direction
constexpr double kCityCarriageHalfWidth = 6.4;  // lanes
constexpr double kCityCurbOffset = 8.6;         // parking lanes between 6.4 and 8.6
constexpr double kCitySidewalkOffset = 12.0;    // sidewalk between 8.6 and 12.0
constexpr double kCityFacadeOffset = 12.5;
constexpr double kCityCameraHeight = 1.65;
constexpr double kCityEgoLane = 4.8;  // right-hand traffic, outer lane

// Builds the static city for a seed. Photographs, when given, replace the procedural facades.
World build_city_world(std::uint64_t seed, const std::vector<cv::Mat>& facade_photos);

// About 1.6 km through the grid, closed so that it can be driven lap after lap: two loops that
// share streets driven in the same direction, and a crossing of the two loops.
Route city_loop_route();
// About 210 m straight along one street, through one crossing.
Route straight_route();

// Adds `count` moving objects following the streets of `route`: cars next to and ahead of the ego
// car (filling a large part of its view), oncoming cars, trucks, buses and pedestrians.
// ego_distance(t) is the ego car's arc length along the route at time t.
void add_city_traffic(World& world, std::shared_ptr<const Route> route,
                      std::function<double(double)> ego_distance, int count, std::uint64_t seed);

}  // namespace sbaslam::sim
