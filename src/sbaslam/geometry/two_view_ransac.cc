#include "sbaslam/geometry/two_view_ransac.h"

#include <numeric>
#include <random>

#include "sbaslam/geometry/epipolar_models.h"

namespace sbaslam::geometry {
namespace {

constexpr int kRefitRounds = 3;

template <typename Estimate, typename Score>
ModelFit run_ransac(const Correspondences& c, const std::vector<MinimalSet>& sets,
                    Estimate estimate, Score score) {
  const NormalizedPoints n1 = normalize_points(c.p1), n2 = normalize_points(c.p2);
  ModelFit best;
  best.score.inliers.assign(c.size(), 0);
  std::vector<int> indices(8);
  bool first = true;
  for (const MinimalSet& set : sets) {
    indices.assign(set.begin(), set.end());
    const Mat3 model = estimate(n1, n2, indices);
    if (!model.allFinite()) continue;
    ModelScore s = score(model, c);
    if (first || s.score > best.score.score) {
      best.model = model;
      best.score = std::move(s);
      first = false;
    }
  }
  // Local optimisation (LO-RANSAC): an 8-point model fits the noise of its sample, so refit on
  // all inliers while that raises the score. With 0.5-1 px of noise this cuts the direction
  // error of the essential matrix's translation several-fold; ORB-SLAM has no such step.
  for (int round = 0; round < kRefitRounds && best.score.inlier_count >= 8; ++round) {
    indices.clear();
    for (int i = 0; i < c.size(); ++i)
      if (best.score.inliers[i]) indices.push_back(i);
    const Mat3 model = estimate(n1, n2, indices);
    if (!model.allFinite()) break;
    ModelScore s = score(model, c);
    if (s.score <= best.score.score) break;
    best.model = model;
    best.score = std::move(s);
  }
  return best;
}

}  // namespace

std::vector<MinimalSet> sample_minimal_sets(int n, int iterations, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<int> pool(n);
  std::vector<MinimalSet> sets(iterations);
  for (MinimalSet& set : sets) {
    std::iota(pool.begin(), pool.end(), 0);
    // Partial Fisher-Yates: the first 8 entries of the pool become the set.
    for (int k = 0; k < 8; ++k) {
      const int pick = k + static_cast<int>(rng() % static_cast<std::uint64_t>(n - k));
      std::swap(pool[k], pool[pick]);
      set[k] = pool[k];
    }
  }
  return sets;
}

ModelFit ransac_homography(const Correspondences& c, const std::vector<MinimalSet>& sets) {
  auto estimate = [](const NormalizedPoints& n1, const NormalizedPoints& n2,
                     const std::vector<int>& indices) -> Mat3 {
    // x2n = Hn x1n with xn = T x  =>  H21 = T2^-1 Hn T1.
    return n2.T.inverse() * homography_dlt(n1.points, n2.points, indices) * n1.T;
  };
  auto score = [](const Mat3& H, const Correspondences& cc) { return score_homography(H, cc); };
  return run_ransac(c, sets, estimate, score);
}

ModelFit ransac_fundamental(const Correspondences& c, const std::vector<MinimalSet>& sets) {
  auto estimate = [](const NormalizedPoints& n1, const NormalizedPoints& n2,
                     const std::vector<int>& indices) -> Mat3 {
    // x2n^T Fn x1n = 0 with xn = T x  =>  F21 = T2^T Fn T1.
    return n2.T.transpose() * fundamental_8point(n1.points, n2.points, indices) * n1.T;
  };
  auto score = [](const Mat3& F, const Correspondences& cc) { return score_fundamental(F, cc); };
  return run_ransac(c, sets, estimate, score);
}

}  // namespace sbaslam::geometry
