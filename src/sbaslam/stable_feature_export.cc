#include "sbaslam/stable_feature_export.h"

#include <limits>

namespace sbaslam {
namespace {

// Reprojection error in undistorted pixels; infinite when the point is behind the camera.
double reprojection_error(const map::KeyFrame& kf, const Vec3& point_w, std::size_t keypoint) {
  const Vec3 p_c = kf.T_cw() * point_w;
  if (!(p_c.z() > 0.0)) return std::numeric_limits<double>::infinity();
  const feature::OrbKeypoint& kp = kf.measurements().keypoints_un[keypoint];
  return (kf.rig().camera.project(p_c) - Vec2(kp.x, kp.y)).norm();
}

saliency::PointObservation observation(const map::KeyFrame& kf, const map::MapPoint& mp,
                                       std::size_t keypoint, const StableFeatureSources& sources) {
  const feature::OrbKeypoint& raw = kf.measurements().keypoints[keypoint];
  const Vec2 file = sources.file_pixel(Vec2(raw.x, raw.y));
  saliency::PointObservation o;
  o.timestamp = kf.timestamp();
  o.image = sources.image_of(kf.timestamp());
  o.x = static_cast<float>(file.x());
  o.y = static_cast<float>(file.y());
  o.octave = raw.octave;
  o.error_px = reprojection_error(kf, mp.position(), keypoint);
  o.level_sigma = kf.rig().levels.scale.at(static_cast<std::size_t>(raw.octave));
  return o;
}

}  // namespace

std::vector<saliency::PointTrack> map_point_tracks(const map::Map& map,
                                                   const StableFeatureSources& sources) {
  std::vector<saliency::PointTrack> tracks;
  for (const map::MapPoint* mp : map.map_points()) {
    if (mp->is_bad()) continue;
    saliency::PointTrack track;
    track.point_id = mp->id();
    for (const auto& [kf, keypoint] : mp->observations())
      if (!kf->is_bad()) track.observations.push_back(observation(*kf, *mp, keypoint, sources));
    tracks.push_back(std::move(track));
  }
  return tracks;
}

}  // namespace sbaslam
