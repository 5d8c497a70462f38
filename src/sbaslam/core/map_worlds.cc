#include "sbaslam/core/map_worlds.h"

namespace sbaslam {
namespace {

std::size_t biggest_map(const std::vector<PoseInMap>& poses,
                        const std::map<std::size_t, std::size_t>& live_keyframes) {
  std::size_t best_id = poses.empty() ? 0 : poses.front().map_id;
  std::size_t best_count = 0;
  for (const auto& [id, count] : live_keyframes) {
    if (count > best_count) {  // ascending ids: a tie keeps the older map
      best_id = id;
      best_count = count;
    }
  }
  return best_id;
}

}  // namespace

TrajectoriesByWorld split_by_world(const std::vector<PoseInMap>& poses,
                                   const std::map<std::size_t, std::size_t>& live_keyframes,
                                   bool maps_share_world) {
  TrajectoriesByWorld out;
  out.main_map_id = biggest_map(poses, live_keyframes);
  for (const PoseInMap& p : poses) {
    if (maps_share_world || p.map_id == out.main_map_id) {
      out.main.push_back(p.stamp, p.pose);
    } else {
      out.own_worlds[p.map_id].push_back(p.stamp, p.pose);
    }
  }
  return out;
}

}  // namespace sbaslam
