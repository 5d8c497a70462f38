#pragma once
// New map points from a keyframe and its covisible neighbours (ORB-SLAM's CreateNewMapPoints):
// unmatched keypoints are paired by descriptor along the epipolar line, triangulated (or taken
// from a stereo depth when it has more parallax), and kept only if they reproject well in both
// keyframes, lie in front of both, and appear at consistent scales.

#include <functional>
#include <optional>
#include <vector>

#include "sbaslam/map/map.h"

namespace sbaslam::mapping {

struct KeypointPair {
  std::size_t first = 0, second = 0;
};

// Unmatched keypoints of kf1 and kf2 that agree in descriptor (TH_LOW), epipolar geometry and
// rotation; one pair per keypoint.
std::vector<KeypointPair> match_for_triangulation(const map::KeyFrame& kf1,
                                                  const map::KeyFrame& kf2);

// Linear (DLT) triangulation of two normalised-plane observations; nullopt when degenerate.
std::optional<Vec3> triangulate_dlt(const Vec2& xn1, const Vec2& xn2, const SE3& T_c1w,
                                    const SE3& T_c2w);

// ORB-SLAM's parallax gate for two rays without stereo depth: cos 0.9998, 1.15 degrees.
constexpr double kOrbSlamMinParallaxCos = 0.9998;

// Returns the new points (already linked to both keyframes). A pair without stereo depth needs
// rays whose cosine is below `min_parallax_cos`. `after_each_neighbour` runs between neighbours,
// where the map is consistent (local mapping yields the map lock there).
std::vector<map::MapPoint*> create_new_map_points(
    map::Map& map, map::KeyFrame* kf, int neighbours,
    double min_parallax_cos = kOrbSlamMinParallaxCos,
    const std::function<void()>& after_each_neighbour = [] {});

}  // namespace sbaslam::mapping
