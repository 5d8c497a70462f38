#include "sbaslam/tracking/projection.h"

#include <set>

#include "sbaslam/map/keyframe.h"
#include "sbaslam/match/orb_matcher.h"

namespace sbaslam::tracking {

match::FrameView frame_view(const Frame& frame, const map::CameraRig& rig) {
  const map::Measurements& m = frame.m();
  return match::FrameView{m.keypoints_un, m.descriptors, m.grid, rig.levels,
                          rig.stereo ? &m.u_right : nullptr};
}

bool is_in_frustum(map::MapPoint& mp, const Frame& frame, const map::CameraRig& rig,
                   double min_view_cos) {
  mp.track_in_view = false;
  const Vec3 p_c = frame.T_cw * mp.position();
  if (p_c.z() <= 0.0) return false;
  const Vec2 uv = rig.camera.project(p_c);
  if (!rig.in_image(uv)) return false;
  const Vec3 po = mp.position() - frame.camera_center();
  const double distance = po.norm();
  if (distance < mp.min_distance() || distance > mp.max_distance()) return false;
  const double view_cos = po.dot(mp.normal()) / distance;
  if (view_cos < min_view_cos) return false;

  mp.track_in_view = true;
  mp.track_proj_x = uv.x();
  mp.track_proj_y = uv.y();
  mp.track_proj_xr = rig.stereo ? uv.x() - rig.bf / p_c.z() : -1.0;
  mp.track_scale_level = mp.predict_level(distance, rig.levels);
  mp.track_view_cos = view_cos;
  return true;
}

int search_from_last_frame(Frame& current, const Frame& last, const map::CameraRig& rig,
                           float radius) {
  // With stereo, forward motion makes points grow (search finer levels' coarser neighbours) and
  // backward motion shrinks them, as in ORB-SLAM.
  const Vec3 t_lc = (last.T_cw * current.T_cw.inverse()).translation();
  const bool forward = rig.stereo && t_lc.z() > rig.baseline();
  const bool backward = rig.stereo && -t_lc.z() > rig.baseline();

  std::vector<match::ProjectedPoint> points;
  std::vector<map::MapPoint*> sources;
  for (std::size_t i = 0; i < last.size(); ++i) {
    map::MapPoint* mp = last.map_points[i];
    if (!mp || last.outlier[i] || mp->is_bad()) continue;
    const Vec3 p_c = current.T_cw * mp->position();
    if (p_c.z() <= 0.0) continue;
    const Vec2 uv = rig.camera.project(p_c);
    if (!rig.in_image(uv)) continue;
    match::ProjectedPoint p;
    p.u = static_cast<float>(uv.x());
    p.v = static_cast<float>(uv.y());
    p.u_right = rig.stereo ? static_cast<float>(uv.x() - rig.bf / p_c.z()) : -1.0f;
    p.level = last.m().keypoints_un[i].octave;
    p.descriptor = mp->descriptor().empty() ? last.m().descriptor(i) : mp->descriptor().ptr();
    p.angle = last.m().keypoints_un[i].angle;
    points.push_back(p);
    sources.push_back(mp);
  }
  match::ProjectionOptions options;
  options.radius = radius;
  options.nn_ratio = 1.0f;
  options.check_orientation = true;
  options.levels_below = forward ? 0 : 1;
  options.levels_above = backward ? 0 : (forward ? 100 : 1);
  if (backward) options.levels_below = 100;
  std::vector<char> taken(current.size(), 0);
  for (std::size_t i = 0; i < current.size(); ++i) taken[i] = current.map_points[i] != nullptr;
  const std::vector<match::Match> matches =
      match::match_by_projection(points, frame_view(current, rig), options, &taken);
  for (const match::Match& m : matches)
    current.map_points[static_cast<std::size_t>(m.train)] =
        sources[static_cast<std::size_t>(m.query)];
  return static_cast<int>(matches.size());
}

int search_local_points(Frame& frame, const std::vector<map::MapPoint*>& points,
                        const map::CameraRig& rig, float radius) {
  std::vector<match::ProjectedPoint> projected;
  std::vector<map::MapPoint*> sources;
  for (map::MapPoint* mp : points) {
    if (!mp->track_in_view || mp->is_bad() || mp->descriptor().empty()) continue;
    match::ProjectedPoint p;
    p.u = static_cast<float>(mp->track_proj_x);
    p.v = static_cast<float>(mp->track_proj_y);
    p.u_right = static_cast<float>(mp->track_proj_xr);
    p.level = mp->track_scale_level;
    p.descriptor = mp->descriptor().ptr();
    // ORB-SLAM widens the window for points seen from an unusual angle.
    p.radius_factor = mp->track_view_cos > 0.998 ? 2.5f : 4.0f;
    projected.push_back(p);
    sources.push_back(mp);
  }
  match::ProjectionOptions options;
  options.radius = radius;
  options.nn_ratio = 0.8f;
  options.levels_below = 1;
  options.levels_above = 0;
  options.check_orientation = false;
  std::vector<char> taken(frame.size(), 0);
  for (std::size_t i = 0; i < frame.size(); ++i)
    taken[i] = frame.map_points[i] && frame.map_points[i]->observation_count() > 0;
  const std::vector<match::Match> matches =
      match::match_by_projection(projected, frame_view(frame, rig), options, &taken);
  for (const match::Match& m : matches) {
    frame.map_points[static_cast<std::size_t>(m.train)] =
        sources[static_cast<std::size_t>(m.query)];
    frame.outlier[static_cast<std::size_t>(m.train)] = 0;
  }
  return static_cast<int>(matches.size());
}

int search_from_keyframe(Frame& frame, const map::KeyFrame& kf, const map::CameraRig& rig,
                         float radius, int max_distance) {
  std::set<const map::MapPoint*> already;
  for (const map::MapPoint* mp : frame.map_points)
    if (mp) already.insert(mp);
  std::vector<match::ProjectedPoint> points;
  std::vector<map::MapPoint*> sources;
  const Vec3 center = frame.camera_center();
  for (std::size_t i = 0; i < kf.keypoint_count(); ++i) {
    map::MapPoint* mp = kf.map_point(i);
    if (!mp || mp->is_bad() || already.count(mp) || mp->descriptor().empty()) continue;
    const Vec3 p_c = frame.T_cw * mp->position();
    if (p_c.z() <= 0.0) continue;
    const Vec2 uv = rig.camera.project(p_c);
    if (!rig.in_image(uv)) continue;
    const double distance = (mp->position() - center).norm();
    if (distance < mp->min_distance() || distance > mp->max_distance()) continue;
    match::ProjectedPoint p;
    p.u = static_cast<float>(uv.x());
    p.v = static_cast<float>(uv.y());
    p.level = mp->predict_level(distance, rig.levels);
    p.descriptor = mp->descriptor().ptr();
    p.angle = kf.measurements().keypoints_un[i].angle;
    points.push_back(p);
    sources.push_back(mp);
  }
  match::ProjectionOptions options;
  options.radius = radius;
  options.nn_ratio = 1.0f;
  options.max_distance = max_distance;
  options.check_orientation = true;
  options.levels_below = 1;
  options.levels_above = 1;
  std::vector<char> taken(frame.size(), 0);
  for (std::size_t i = 0; i < frame.size(); ++i) taken[i] = frame.map_points[i] != nullptr;
  const std::vector<match::Match> matches =
      match::match_by_projection(points, frame_view(frame, rig), options, &taken);
  for (const match::Match& m : matches)
    frame.map_points[static_cast<std::size_t>(m.train)] =
        sources[static_cast<std::size_t>(m.query)];
  return static_cast<int>(matches.size());
}

std::vector<PointMatch> match_keyframe_points_by_descriptor(const map::KeyFrame& kf,
                                                            const Frame& frame, float nn_ratio) {
  std::vector<std::size_t> kf_index;
  for (std::size_t i = 0; i < kf.keypoint_count(); ++i)
    if (kf.map_point(i) && !kf.map_point(i)->is_bad()) kf_index.push_back(i);
  if (kf_index.empty()) return {};
  const cv::Mat query = match::descriptor_rows(kf.measurements().descriptors, kf_index);
  match::BruteForceOptions options;
  options.max_distance = match::kThresholdLow;
  options.nn_ratio = nn_ratio;
  options.cross_check = false;
  std::vector<PointMatch> out;
  for (const match::Match& m : match::match_brute_force(query, frame.m().descriptors, options))
    out.push_back({static_cast<std::size_t>(m.train),
                   kf.map_point(kf_index[static_cast<std::size_t>(m.query)])});
  return out;
}

}  // namespace sbaslam::tracking
