#include "sbaslam/loop/kmedians.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace sbaslam::loop {
namespace {

using Points = std::vector<const std::uint8_t*>;

BinaryDescriptor to_descriptor(const std::uint8_t* p) {
  BinaryDescriptor d;
  std::memcpy(d.data(), p, d.size());
  return d;
}

std::uint64_t squared_distance(const std::uint8_t* a, const BinaryDescriptor& b) {
  const auto d = static_cast<std::uint64_t>(match::descriptor_distance(a, b.data()));
  return d * d;
}

// Squared distances to the nearest centre once `centre` joins the centres whose squared distances
// are `d2`; returns their sum (the k-means potential).
std::uint64_t with_centre(const Points& points, const std::uint8_t* centre,
                          const std::vector<std::uint64_t>& d2, std::vector<std::uint64_t>& out) {
  const BinaryDescriptor c = to_descriptor(centre);
  std::uint64_t potential = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    out[i] = std::min(d2[i], squared_distance(points[i], c));
    potential += out[i];
  }
  return potential;
}

// Greedy k-means++ seeding (as scikit-learn's): each new centre is the best, by the potential it
// leaves, of 2 + log(k) draws weighted by squared distance. Plain k-means++ often seeds two centres
// in one tight cluster and none in another, which the iterations cannot undo. The draws are
// integers modulo the integer potential, so the centres depend on the generator alone.
std::vector<BinaryDescriptor> seed_centres(const Points& points, std::size_t k,
                                           std::mt19937_64& rng) {
  std::vector<BinaryDescriptor> centres{to_descriptor(points[rng() % points.size()])};
  std::vector<std::uint64_t> d2(points.size()), trial(points.size()), best(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) d2[i] = squared_distance(points[i], centres[0]);
  std::uint64_t potential = std::accumulate(d2.begin(), d2.end(), std::uint64_t{0});
  const int trials = 2 + static_cast<int>(std::log(static_cast<double>(k)));
  while (centres.size() < k && potential > 0) {  // potential 0: fewer distinct points than k
    std::uint64_t best_potential = potential + 1;
    std::size_t best_pick = 0;
    for (int t = 0; t < trials; ++t) {
      std::uint64_t r = rng() % potential;
      std::size_t pick = 0;
      for (; r >= d2[pick]; ++pick) r -= d2[pick];
      const std::uint64_t p = with_centre(points, points[pick], d2, trial);
      if (p >= best_potential) continue;
      best_potential = p;
      best_pick = pick;
      best.swap(trial);
    }
    centres.push_back(to_descriptor(points[best_pick]));
    d2.swap(best);
    potential = best_potential;
  }
  return centres;
}

// Assigns each point to its nearest centre (the first on ties); true if any assignment changed.
bool assign(const Points& points, const std::vector<BinaryDescriptor>& centres,
            std::vector<std::uint32_t>& assignment) {
  bool changed = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint32_t best = 0;
    int best_distance = match::kMaxDescriptorDistance + 1;
    for (std::uint32_t c = 0; c < centres.size(); ++c) {
      const int d = match::descriptor_distance(points[i], centres[c].data());
      if (d < best_distance) {
        best_distance = d;
        best = c;
      }
    }
    changed |= assignment[i] != best;
    assignment[i] = best;
  }
  return changed;
}

// Each centre becomes the bitwise majority of its points; a tie sets the bit, as in DBoW2. An
// emptied cluster keeps its centre.
void update_centres(const Points& points, const std::vector<std::uint32_t>& assignment,
                    std::vector<BinaryDescriptor>& centres) {
  std::vector<std::array<std::uint32_t, 8 * match::kDescriptorBytes>> ones(centres.size());
  for (auto& counts : ones) counts.fill(0);
  std::vector<std::uint32_t> sizes(centres.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    auto& counts = ones[assignment[i]];
    ++sizes[assignment[i]];
    for (int j = 0; j < match::kDescriptorBytes; ++j)
      for (int b = 0; b < 8; ++b) counts[8 * j + b] += (points[i][j] >> b) & 1u;
  }
  for (std::size_t c = 0; c < centres.size(); ++c) {
    if (sizes[c] == 0) continue;
    for (int j = 0; j < match::kDescriptorBytes; ++j) {
      std::uint8_t byte = 0;
      for (int b = 0; b < 8; ++b)
        if (2 * ones[c][8 * j + b] >= sizes[c]) byte |= static_cast<std::uint8_t>(1u << b);
      centres[c][static_cast<std::size_t>(j)] = byte;
    }
  }
}

// Groups points by the centre they were last assigned to, dropping empty clusters. The centres
// are those the assignment used, so descending the tree finds each training point's own cluster.
DescriptorClusters group(const Points& points, const std::vector<BinaryDescriptor>& centres,
                         const std::vector<std::uint32_t>& assignment) {
  std::vector<Points> members(centres.size());
  for (std::size_t i = 0; i < points.size(); ++i) members[assignment[i]].push_back(points[i]);
  DescriptorClusters out;
  for (std::size_t c = 0; c < centres.size(); ++c) {
    if (members[c].empty()) continue;
    out.centres.push_back(centres[c]);
    out.members.push_back(std::move(members[c]));
  }
  return out;
}

DescriptorClusters kmedians(const Points& points, std::size_t k, int iterations,
                            std::mt19937_64& rng) {
  std::vector<BinaryDescriptor> centres = seed_centres(points, k, rng);
  std::vector<std::uint32_t> assignment(points.size(), 0);
  assign(points, centres, assignment);
  for (int it = 1; it < iterations && centres.size() > 1; ++it) {
    update_centres(points, assignment, centres);
    if (!assign(points, centres, assignment)) break;
  }
  return group(points, centres, assignment);
}

// With no more points than children, each distinct descriptor is its own cluster (DBoW2 makes
// one per descriptor; duplicates would only add words that no descriptor ever reaches).
DescriptorClusters distinct_points(Points points) {
  const auto less = [](const std::uint8_t* a, const std::uint8_t* b) {
    return std::memcmp(a, b, match::kDescriptorBytes) < 0;
  };
  std::sort(points.begin(), points.end(), less);
  DescriptorClusters out;
  for (const std::uint8_t* p : points) {
    if (out.members.empty() || less(out.members.back().front(), p)) {
      out.centres.push_back(to_descriptor(p));
      out.members.emplace_back();
    }
    out.members.back().push_back(p);
  }
  return out;
}

}  // namespace

DescriptorClusters cluster_descriptors(std::vector<const std::uint8_t*> points, std::size_t k,
                                       int iterations, std::mt19937_64& rng) {
  if (points.size() <= k) return distinct_points(std::move(points));
  return kmedians(points, k, iterations, rng);
}

}  // namespace sbaslam::loop
