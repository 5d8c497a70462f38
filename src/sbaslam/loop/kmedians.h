#pragma once
// One step of the vocabulary's hierarchical clustering: k-medians over 256-bit binary
// descriptors (Hamming distance, bitwise-majority centres), as DBoW2 trains its trees.

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "sbaslam/match/hamming.h"

namespace sbaslam::loop {

using BinaryDescriptor = std::array<std::uint8_t, match::kDescriptorBytes>;

// Non-empty clusters: centres[c] and the points (pointers to 32 bytes each) assigned to it.
struct DescriptorClusters {
  std::vector<BinaryDescriptor> centres;
  std::vector<std::vector<const std::uint8_t*>> members;
};

// At most k clusters of `points`. With no more than k points, each distinct descriptor is its own
// cluster. Otherwise greedy k-means++ seeding (each centre the best of 2 + log k draws weighted by
// squared distance; integer draws from `rng`, so the result depends on the generator's state
// alone), then up to `iterations` assignment rounds, stopping early when no assignment changes.
// Every point ends in the cluster of its nearest centre (the first on ties), so descending a tree
// built from these centres finds a training point's cluster.
DescriptorClusters cluster_descriptors(std::vector<const std::uint8_t*> points, std::size_t k,
                                       int iterations, std::mt19937_64& rng);

}  // namespace sbaslam::loop
