#pragma once
// RANSAC for the homography and the fundamental matrix over shared minimal sets (ORB-SLAM draws
// the 8-point sets once and fits both models on the same sets, so their scores compare like with
// like). Both searches are deterministic given the sets.

#include <array>
#include <cstdint>
#include <vector>

#include "sbaslam/geometry/correspondences.h"

namespace sbaslam::geometry {

using MinimalSet = std::array<int, 8>;

// `iterations` sets of 8 distinct indices in [0, n), from a 64-bit Mersenne twister seeded with
// `seed`. Indices are drawn as rng() % remaining (bias below 1e-15 for any realistic n), so the
// sets are the same on every standard library. Needs n >= 8.
std::vector<MinimalSet> sample_minimal_sets(int n, int iterations, std::uint64_t seed);

struct ModelFit {
  Mat3 model = Mat3::Zero();  // H21 or F21 between pixels
  ModelScore score;
};

// The best-scoring homography / fundamental matrix over the sets (the first one on ties), then
// refitted on all its inliers for as long as that raises the score.
ModelFit ransac_homography(const Correspondences& c, const std::vector<MinimalSet>& sets);
ModelFit ransac_fundamental(const Correspondences& c, const std::vector<MinimalSet>& sets);

}  // namespace sbaslam::geometry
