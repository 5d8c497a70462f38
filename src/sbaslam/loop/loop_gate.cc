#include "sbaslam/loop/loop_gate.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "sbaslam/loop/loop_correction.h"

namespace sbaslam::loop {
namespace {

// Along the keyframes from `from` to `to` (from.id() <= to.id()), in the order they were made.
double path_by_id(const map::Map& map, const map::KeyFrame& from, const map::KeyFrame& to) {
  double length = 0.0;
  const map::KeyFrame* previous = nullptr;
  for (const map::KeyFrame* kf : map.keyframes()) {
    if (kf->id() < from.id() || kf->id() > to.id() || kf->is_bad()) continue;
    if (previous && same_map(map, *previous, *kf))
      length += (kf->camera_center() - previous->camera_center()).norm();
    previous = kf;
  }
  return length;
}

double path_either_way(const map::Map& map, const map::KeyFrame& a, const map::KeyFrame& b) {
  return a.id() <= b.id() ? path_by_id(map, a, b) : path_by_id(map, b, a);
}

}  // namespace

double driven_path_length(const map::Map& map, const map::KeyFrame& a, const map::KeyFrame& b,
                          std::size_t first_run_keyframe) {
  const bool a_loaded = a.id() < first_run_keyframe, b_loaded = b.id() < first_run_keyframe;
  if (a_loaded == b_loaded) return path_either_way(map, a, b);
  const map::KeyFrame& loaded = a_loaded ? a : b;
  const map::KeyFrame& ours = a_loaded ? b : a;
  const std::vector<map::KeyFrame*> keyframes = map.keyframes();
  const auto first_ours =
      std::find_if(keyframes.begin(), keyframes.end(),
                   [&](const map::KeyFrame* kf) { return kf->id() >= first_run_keyframe; });
  if (first_ours == keyframes.end()) return path_either_way(map, a, b);
  const map::KeyFrame* joined = nullptr;
  double nearest = std::numeric_limits<double>::infinity();
  for (const map::KeyFrame* kf : keyframes) {
    if (kf->id() >= first_run_keyframe || !same_map(map, *kf, **first_ours)) continue;
    const double d = (kf->camera_center() - (*first_ours)->camera_center()).norm();
    if (d < nearest) {
      nearest = d;
      joined = kf;
    }
  }
  // This run never joined the loaded map (it started a map of its own): no shorter way is known.
  if (!joined) return path_either_way(map, a, b);
  return path_either_way(map, loaded, *joined) + path_either_way(map, **first_ours, ours);
}

Loss loss_before(const map::Map& map, const map::KeyFrame& root, std::size_t first_run_keyframe) {
  constexpr std::size_t kSpeedKeyframes = 5;
  std::vector<const map::KeyFrame*> before;
  for (const map::KeyFrame* kf : map.keyframes())
    if (!kf->is_bad() && kf->id() < root.id() && kf->id() >= first_run_keyframe)
      before.push_back(kf);
  Loss loss;
  loss.anchored = !before.empty() || first_run_keyframe == 0;
  if (before.empty()) return loss;
  const map::KeyFrame* last = before.back();
  loss.seconds = std::max(0.0, root.timestamp() - last->timestamp());
  const map::KeyFrame* first = before[before.size() - std::min(before.size(), kSpeedKeyframes + 1)];
  const double dt = last->timestamp() - first->timestamp();
  if (dt > 0.0) loss.speed = (last->camera_center() - first->camera_center()).norm() / dt;
  return loss;
}

}  // namespace sbaslam::loop
