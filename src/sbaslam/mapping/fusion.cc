#include "sbaslam/mapping/fusion.h"

#include "sbaslam/match/hamming.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::mapping {
namespace {

// Best keypoint of kf for a projected point, or -1: octave consistent with the predicted level,
// reprojection error within the chi-square bound, descriptor distance within TH_LOW.
int best_keypoint(const map::KeyFrame& kf, const map::MapPoint& mp, const Vec2& uv, double u_right,
                  int predicted_level, double radius) {
  const map::CameraRig& rig = kf.rig();
  const map::Measurements& m = kf.measurements();
  const std::vector<std::size_t> nearby = kf.features_in_area(
      uv.x(), uv.y(), radius * rig.levels.scale[static_cast<std::size_t>(predicted_level)]);
  int best = -1, best_distance = match::kThresholdLow + 1;
  for (std::size_t i : nearby) {
    const feature::OrbKeypoint& kp = m.keypoints_un[i];
    if (kp.octave < predicted_level - 1 || kp.octave > predicted_level) continue;
    const double inv_sigma2 = rig.levels.inv_sigma2[static_cast<std::size_t>(kp.octave)];
    double e2 = (uv - Vec2(kp.x, kp.y)).squaredNorm();
    if (m.u_right[i] >= 0.0f) {
      e2 += (u_right - m.u_right[i]) * (u_right - m.u_right[i]);
      if (e2 * inv_sigma2 > 7.8) continue;
    } else if (e2 * inv_sigma2 > 5.99) {
      continue;
    }
    const int d = match::descriptor_distance(mp.descriptor().ptr(), m.descriptor(i));
    if (d < best_distance) {
      best_distance = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace

int fuse_into_keyframe(map::KeyFrame* kf, const std::vector<map::MapPoint*>& points,
                       double radius) {
  const map::CameraRig& rig = kf->rig();
  int fused = 0;
  for (map::MapPoint* mp : points) {
    if (!mp || mp->is_bad() || mp->descriptor().empty() || mp->is_in_keyframe(kf)) continue;
    const Vec3 p_c = kf->T_cw() * mp->position();
    if (p_c.z() <= 0.0) continue;
    const Vec2 uv = rig.camera.project(p_c);
    if (!rig.in_image(uv)) continue;
    const Vec3 po = mp->position() - kf->camera_center();
    const double distance = po.norm();
    if (distance < mp->min_distance() || distance > mp->max_distance()) continue;
    if (po.dot(mp->normal()) < 0.5 * distance) continue;
    const int level = mp->predict_level(distance, rig.levels);
    const double u_right = uv.x() - rig.bf / p_c.z();
    const int best = best_keypoint(*kf, *mp, uv, u_right, level, radius);
    if (best < 0) continue;

    map::MapPoint* existing = kf->map_point(static_cast<std::size_t>(best));
    if (existing && !existing->is_bad()) {
      if (existing->observation_count() > mp->observation_count()) {
        mp->replace_with(existing);
      } else {
        existing->replace_with(mp);
      }
    } else {
      mp->add_observation(kf, static_cast<std::size_t>(best));
      kf->add_map_point(mp, static_cast<std::size_t>(best));
    }
    ++fused;
  }
  return fused;
}

void search_in_neighbours(map::KeyFrame* kf, int neighbours,
                          const std::function<void()>& after_each_target) {
  std::vector<map::KeyFrame*> targets;
  for (map::KeyFrame* k : kf->best_covisibles(static_cast<std::size_t>(neighbours))) {
    if (k->is_bad() || k->fuse_target_for_keyframe == kf->id()) continue;
    k->fuse_target_for_keyframe = kf->id();
    targets.push_back(k);
  }
  const std::size_t direct = targets.size();
  for (std::size_t i = 0; i < direct; ++i)
    for (map::KeyFrame* k2 : targets[i]->best_covisibles(5)) {
      if (k2->is_bad() || k2 == kf || k2->fuse_target_for_keyframe == kf->id()) continue;
      k2->fuse_target_for_keyframe = kf->id();
      targets.push_back(k2);
    }

  for (map::KeyFrame* target : targets) {
    after_each_target();
    fuse_into_keyframe(target, kf->map_points());
  }

  std::vector<map::MapPoint*> candidates;
  for (map::KeyFrame* target : targets)
    for (map::MapPoint* mp : target->map_points()) {
      if (!mp || mp->is_bad() || mp->fuse_candidate_for_keyframe == kf->id()) continue;
      mp->fuse_candidate_for_keyframe = kf->id();
      candidates.push_back(mp);
    }
  fuse_into_keyframe(kf, candidates);

  for (map::MapPoint* mp : kf->map_points()) {
    if (!mp || mp->is_bad()) continue;
    mp->update_descriptor();
    mp->update_normal_and_depth();
  }
  kf->update_connections();
}

}  // namespace sbaslam::mapping
