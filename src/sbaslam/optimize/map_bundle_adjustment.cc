#include "sbaslam/optimize/map_bundle_adjustment.h"

#include <unordered_map>

#include "sbaslam/optimize/map_observation.h"
#include "sbaslam/saliency/observation_weight.h"

namespace sbaslam::optimize {
namespace {

// Collects keyframes and points into the problem, with index maps from object to slot.
class ProblemBuilder {
 public:
  ProblemBuilder(MapBundleAdjustment& ba, const map::CameraRig& rig,
                 const MapBaWeighting& weighting)
      : ba_(ba), rig_(rig), weighting_(weighting) {
    ba_.problem.camera = rectified_camera(rig);
  }

  void add_keyframe(map::KeyFrame* kf, bool fixed) {
    if (keyframe_slot_.count(kf)) return;
    keyframe_slot_[kf] = static_cast<int>(ba_.keyframes.size());
    ba_.keyframes.push_back(kf);
    ba_.problem.keyframes.push_back({kf->T_cw(), fixed || kf->is_origin()});
  }

  void add_point_with_observations(map::MapPoint* mp) {
    if (point_slot_.count(mp)) return;
    const int slot = static_cast<int>(ba_.points.size());
    point_slot_[mp] = slot;
    ba_.points.push_back(mp);
    ba_.problem.points.push_back({mp->position(), false});
    for (const auto& [kf, index] : mp->observations()) {
      if (kf->is_bad()) continue;
      const auto it = keyframe_slot_.find(kf);
      if (it == keyframe_slot_.end()) continue;  // caller adds fixed keyframes first
      BaObservation o;
      o.keyframe = it->second;
      o.point = slot;
      o.pixel = observation_of(kf->measurements(), index, rig_);
      if (weighting_.point_depth) weigh_by_point_depth(*kf, index, mp->position(), o.pixel);
      ba_.problem.observations.push_back(o);
      ba_.observation_keypoint.push_back(index);
    }
  }

  bool has_keyframe(map::KeyFrame* kf) const { return keyframe_slot_.count(kf) > 0; }

 private:
  void weigh_by_point_depth(const map::KeyFrame& kf, std::size_t index, const Vec3& position,
                            PixelObservation& pixel) {
    const map::Measurements& m = kf.measurements();
    if (m.s_init.empty()) return;
    auto near = near_.find(&kf);
    if (near == near_.end())
      near = near_.emplace(&kf, point_depth_near(kf, rig_, *weighting_.point_depth)).first;
    const double z = (kf.T_cw() * position).z();
    if (!(z > 0.0) || !(near->second > 0.0)) return;
    pixel.weight =
        saliency::point_depth_weight(m.s_init[index], z, near->second, *weighting_.point_depth);
  }

  MapBundleAdjustment& ba_;
  const map::CameraRig& rig_;
  const MapBaWeighting& weighting_;
  std::unordered_map<const map::KeyFrame*, double> near_;  // point_depth_near per keyframe
  std::unordered_map<map::KeyFrame*, int> keyframe_slot_;
  std::unordered_map<map::MapPoint*, int> point_slot_;
};

}  // namespace

double point_depth_near(const map::KeyFrame& kf, const map::CameraRig& rig,
                        const SaliencySettings& settings) {
  if (settings.depth_near) {
    if (*settings.depth_near > 0.0) return *settings.depth_near;
    return kf.scene_depth_quantile(0.0);
  }
  return rig.stereo ? rig.th_depth : kf.scene_depth_quantile(0.5);
}

MapBundleAdjustment build_local_bundle_adjustment(map::KeyFrame* kf, const map::CameraRig& rig,
                                                  std::size_t max_local_keyframes,
                                                  const MapBaWeighting& weighting) {
  MapBundleAdjustment ba;
  ProblemBuilder builder(ba, rig, weighting);
  std::vector<map::KeyFrame*> local{kf};
  for (map::KeyFrame* neighbour : kf->best_covisibles(max_local_keyframes))
    if (!neighbour->is_bad()) local.push_back(neighbour);
  for (map::KeyFrame* k : local) builder.add_keyframe(k, false);

  std::vector<map::MapPoint*> points;
  for (map::KeyFrame* k : local)
    for (map::MapPoint* mp : k->map_points()) {
      if (!mp || mp->is_bad() || mp->ba_local_for_keyframe == kf->id()) continue;
      mp->ba_local_for_keyframe = kf->id();
      points.push_back(mp);
    }
  // Keyframes that see local points but are not local stay fixed.
  for (map::MapPoint* mp : points)
    for (const auto& [other, index] : mp->observations())
      if (!other->is_bad() && !builder.has_keyframe(other)) builder.add_keyframe(other, true);
  for (map::MapPoint* mp : points) builder.add_point_with_observations(mp);
  return ba;
}

MapBundleAdjustment build_global_bundle_adjustment(map::Map& map, const map::CameraRig& rig,
                                                   const MapBaWeighting& weighting) {
  return build_bundle_adjustment(map.keyframes(), rig, weighting);
}

MapBundleAdjustment build_bundle_adjustment(const std::vector<map::KeyFrame*>& keyframes,
                                            const map::CameraRig& rig,
                                            const MapBaWeighting& weighting) {
  MapBundleAdjustment ba;
  ProblemBuilder builder(ba, rig, weighting);
  for (map::KeyFrame* kf : keyframes)
    if (!kf->is_bad()) builder.add_keyframe(kf, false);
  for (map::KeyFrame* kf : keyframes)
    for (map::MapPoint* mp : kf->map_points())
      if (mp && !mp->is_bad()) builder.add_point_with_observations(mp);
  return ba;
}

void solve_map_bundle_adjustment(MapBundleAdjustment& ba, const BundleAdjusterOptions& options,
                                 const std::atomic<bool>* abort) {
  BundleAdjusterOptions with_abort = options;
  with_abort.abort = abort;
  ba.report = bundle_adjust(ba.problem, with_abort);
}

int apply_map_bundle_adjustment(MapBundleAdjustment& ba) {
  if (!ba.report.solved) return 0;
  int removed = 0;
  for (std::size_t i = 0; i < ba.problem.observations.size(); ++i) {
    if (!ba.report.outlier[i]) continue;
    const BaObservation& o = ba.problem.observations[i];
    map::KeyFrame* kf = ba.keyframes[static_cast<std::size_t>(o.keyframe)];
    map::MapPoint* mp = ba.points[static_cast<std::size_t>(o.point)];
    if (kf->is_bad() || mp->is_bad() || kf->map_point(ba.observation_keypoint[i]) != mp) continue;
    kf->erase_map_point(ba.observation_keypoint[i]);
    mp->erase_observation(kf);
    ++removed;
  }
  for (std::size_t k = 0; k < ba.keyframes.size(); ++k)
    if (!ba.problem.keyframes[k].fixed && !ba.keyframes[k]->is_bad())
      ba.keyframes[k]->set_pose(ba.problem.keyframes[k].T_cw);
  for (std::size_t p = 0; p < ba.points.size(); ++p) {
    if (ba.points[p]->is_bad()) continue;
    ba.points[p]->set_position(ba.problem.points[p].position);
    ba.points[p]->update_normal_and_depth();
  }
  return removed;
}

}  // namespace sbaslam::optimize
