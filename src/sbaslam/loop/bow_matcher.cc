#include "sbaslam/loop/bow_matcher.h"

#include <algorithm>
#include <limits>

#include "sbaslam/match/hamming.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::loop {
namespace {

constexpr float kNearestRatio = 0.75f;

bool has_good_point(const map::KeyFrame& kf, std::size_t i) {
  const map::MapPoint* mp = kf.map_point(i);
  return mp && !mp->is_bad();
}

// Best keypoint of kf2 among `candidates` for descriptor d1, or -1.
long best_in_node(const std::uint8_t* d1, const map::KeyFrame& kf2,
                  const std::vector<std::size_t>& candidates, const std::vector<char>& taken) {
  int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max();
  long best_index = -1;
  for (std::size_t i2 : candidates) {
    if (taken[i2] || !has_good_point(kf2, i2)) continue;
    const int d = match::descriptor_distance(d1, kf2.measurements().descriptor(i2));
    if (d < best) {
      second = best;
      best = d;
      best_index = static_cast<long>(i2);
    } else if (d < second) {
      second = d;
    }
  }
  if (best > match::kThresholdLow) return -1;
  if (static_cast<float>(best) >= kNearestRatio * static_cast<float>(second)) return -1;
  return best_index;
}

}  // namespace

std::vector<KeypointPair> match_keyframes_by_bow(const map::KeyFrame& kf1,
                                                 const FeatureVector& features1,
                                                 const map::KeyFrame& kf2,
                                                 const FeatureVector& features2) {
  std::vector<KeypointPair> pairs;
  std::vector<char> taken(kf2.keypoint_count(), 0);
  match::RotationConsistency rotation;
  auto it1 = features1.begin();
  auto it2 = features2.begin();
  // Both maps are ordered by node: walk them together.
  while (it1 != features1.end() && it2 != features2.end()) {
    if (it1->first < it2->first) {
      ++it1;
      continue;
    }
    if (it2->first < it1->first) {
      ++it2;
      continue;
    }
    for (std::size_t i1 : it1->second) {
      if (!has_good_point(kf1, i1)) continue;
      const long i2 = best_in_node(kf1.measurements().descriptor(i1), kf2, it2->second, taken);
      if (i2 < 0) continue;
      taken[static_cast<std::size_t>(i2)] = 1;
      rotation.add(static_cast<int>(pairs.size()), kf1.measurements().keypoints_un[i1].angle,
                   kf2.measurements().keypoints_un[static_cast<std::size_t>(i2)].angle);
      pairs.push_back({i1, static_cast<std::size_t>(i2)});
    }
    ++it1;
    ++it2;
  }
  const std::vector<int> inconsistent = rotation.inconsistent();
  std::vector<KeypointPair> kept;
  kept.reserve(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (!std::binary_search(inconsistent.begin(), inconsistent.end(), static_cast<int>(k)))
      kept.push_back(pairs[k]);
  return kept;
}

}  // namespace sbaslam::loop
