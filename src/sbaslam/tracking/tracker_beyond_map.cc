// The tracker's localization mode beyond the loaded map (ORB-SLAM3's mbVO): visual odometry on
// stereo points of the last frame, relocalisation in the map near where odometry puts the camera.

#include <spdlog/spdlog.h>

#include <opencv2/core.hpp>
#include <random>

#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/tracking/frame_pose.h"
#include "sbaslam/tracking/tracker.h"

namespace sbaslam::tracking {
namespace {

// Visual odometry outside the map: matches to the last frame's stereo points (ORB-SLAM3: 20).
constexpr int kMinOdometryInliers = 20;
// Odometry has no map points to lean on: its temporal points reach this far into the stereo
// points, far ones included (at a crossing the nearest 100 lay on the road's stripes).
constexpr int kMinOdometryPoints = 400;

}  // namespace

bool Tracker::track_beyond_map(Frame& frame, bool& by_odometry) {
  // ORB-SLAM3's localization mode (mbVO) computes both poses too, and lets relocalisation win.
  Frame odometry_frame = frame;
  const MotionModelInliers odometry = odometry_pose(odometry_frame);
  const bool moved = odometry.all >= kMinOdometryInliers;
  spdlog::debug("frame {}: odometry {} inliers ({} map points), path {:.1f}", frame.id,
                odometry.all, odometry.map_points, odometry_path_);
  const std::optional<PosePrior> prior =
      localization_prior(frame.id, moved ? &odometry_frame.T_cw : nullptr);
  if (relocalize(frame, prior) && track_local_map(frame)) return true;
  if (!moved) return false;
  frame = std::move(odometry_frame);
  by_odometry = true;
  return true;
}

Tracker::MotionModelInliers Tracker::odometry_pose(Frame& frame) {
  Frame anchor;
  const Frame* from = &last_frame_;
  if (last_frame_.has_pose && velocity_) {
    Frame by_motion = frame;
    const MotionModelInliers inliers = track_with_motion_model(by_motion, kMinOdometryPoints);
    if (inliers.all >= kMinOdometryInliers) {
      frame = std::move(by_motion);
      return inliers;
    }
  } else if (last_frame_.has_pose) {
    add_temporal_points(last_frame_, kMinOdometryPoints);
  } else if (odometry_anchor_ && odometry_anchor_->id == last_pose_frame_id_ &&
             frame.id - last_pose_frame_id_ <= static_cast<std::size_t>(options_.max_lost_frames)) {
    anchor = *odometry_anchor_;
    add_temporal_points(anchor, kMinOdometryPoints);
    from = &anchor;
  } else {
    return {};
  }
  return {0, match_points_by_descriptor(frame, *from)};
}

int Tracker::match_points_by_descriptor(Frame& frame, const Frame& from) const {
  std::vector<std::size_t> from_keypoints;
  for (std::size_t i = 0; i < from.size(); ++i)
    if (from.map_points[i]) from_keypoints.push_back(i);
  if (static_cast<int>(from_keypoints.size()) < kMinOdometryInliers) return 0;
  match::BruteForceOptions options;
  options.max_distance = match::kThresholdLow;
  options.nn_ratio = 0.8f;
  const std::vector<match::Match> matches = match::match_brute_force(
      match::descriptor_rows(from.m().descriptors, from_keypoints), frame.m().descriptors, options);
  // Without a guess of the motion (frames may have passed since `from`), the pose comes from a
  // seeded PnP RANSAC first: pose optimisation from `from`'s pose called every match an outlier.
  std::vector<Vec3> points;
  std::vector<Vec2> pixels;
  std::vector<int> levels;
  for (const match::Match& m : matches) {
    const feature::OrbKeypoint& kp = frame.m().keypoints_un[static_cast<std::size_t>(m.train)];
    points.push_back(
        from.map_points[from_keypoints[static_cast<std::size_t>(m.query)]]->position());
    pixels.emplace_back(kp.x, kp.y);
    levels.push_back(kp.octave);
  }
  std::mt19937_64 rng(seed_ + frame.id);
  const PnpResult pnp = solve_pnp_ransac(points, pixels, levels, rig_, PnpRansacOptions{}, rng);
  if (!pnp.success) return 0;
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  for (std::size_t j = 0; j < matches.size(); ++j)
    if (pnp.inlier[j])
      frame.map_points[static_cast<std::size_t>(matches[j].train)] =
          from.map_points[from_keypoints[static_cast<std::size_t>(matches[j].query)]];
  frame.set_pose(pnp.T_cw);
  return optimize_frame_pose(frame, rig_);
}

std::optional<PosePrior> Tracker::localization_prior(std::size_t frame_id,
                                                     const SE3* odometry_T_cw) const {
  if (!options_.localization_only || !rig_.stereo) return std::nullopt;
  const double drift =
      options_.odometry_gate_base + options_.odometry_gate_per_path * odometry_path_;
  if (odometry_T_cw) return PosePrior{odometry_T_cw->inverse().translation(), drift};
  // Without odometry on this frame: the last pose, and room for twice the last speed since.
  const std::size_t unposed = frame_id - last_pose_frame_id_;
  if (!last_known_T_cw_ || unposed > static_cast<std::size_t>(options_.max_lost_frames))
    return std::nullopt;  // long enough to have been carried anywhere
  return PosePrior{last_known_T_cw_->inverse().translation(),
                   drift + 2.0 * last_step_ * static_cast<double>(unposed)};
}

bool Tracker::is_temporal_point(const map::MapPoint* mp) {
  return mp && mp->observation_count() == 0 && mp->reference_keyframe() == nullptr;
}

void Tracker::drop_temporal_points(Frame& frame) {
  for (map::MapPoint*& mp : frame.map_points)
    if (is_temporal_point(mp)) mp = nullptr;
}

}  // namespace sbaslam::tracking
