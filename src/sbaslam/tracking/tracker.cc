#include "sbaslam/tracking/tracker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <mutex>

#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/tracking/frame_pose.h"
#include "sbaslam/tracking/projection.h"

namespace sbaslam::tracking {
namespace {

constexpr int kMaxLocalKeyframes = 80;
constexpr int kMinTrackedInliers = 30;
constexpr int kMinInliersAfterRelocalization = 50;
// Stereo keyframes keep the closest new points, at least this many.
constexpr int kMinNewStereoPoints = 100;

// Indices of the keypoints with a valid depth, nearest first.
std::vector<std::size_t> keypoints_by_depth(const map::Measurements& m) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (m.depth[i] > 0.0f) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&m](std::size_t a, std::size_t b) { return m.depth[a] < m.depth[b]; });
  return order;
}

}  // namespace

Tracker::Tracker(map::Map& map, const map::CameraRig& rig, KeyframeSink& mapper,
                 TrackerOptions options, std::uint64_t seed)
    : map_(map), rig_(rig), mapper_(mapper), options_(options), relocalizer_(rig, seed) {}

TrackingState Tracker::track(Frame frame) {
  std::unique_lock<std::mutex> lock(map_.mutex());
  if (state_ == TrackingState::kNotInitialized) {
    if (rig_.stereo) initialize_stereo(frame);
    record(frame);
    last_frame_ = std::move(frame);
    return state_;
  }

  bool ok = false;
  if (state_ == TrackingState::kOk) {
    replace_bad_points(last_frame_);
    if (!velocity_ || frame.id < last_relocalization_frame_id_ + 2) {
      ok = track_reference_keyframe(frame);
    } else {
      ok = track_with_motion_model(frame) || track_reference_keyframe(frame);
    }
  } else {
    ok = relocalize(frame);
  }
  if (!frame.reference_keyframe) frame.reference_keyframe = reference_keyframe_;
  if (ok) ok = track_local_map(frame);
  if (!ok && state_ == TrackingState::kOk) {
    // Lost in this frame: try to relocalise at once before giving up on the map.
    spdlog::warn("frame {}: tracking lost", frame.id);
    ok = relocalize(frame) && track_local_map(frame);
  }

  if (ok) {
    state_ = TrackingState::kOk;
    velocity_ = last_frame_.has_pose ? std::optional<SE3>(frame.T_cw * last_frame_.T_cw.inverse())
                                     : std::nullopt;
    last_known_T_cw_ = frame.T_cw;
    if (need_new_keyframe(frame)) create_keyframe(frame);
    // Outliers stay in the new keyframe for BA to judge, but must not steer the next frame.
    frame.discard_outliers();
  } else {
    state_ = TrackingState::kLost;
    frame.has_pose = false;
    velocity_.reset();
    if (rig_.stereo) start_new_map(frame);
  }
  if (!frame.reference_keyframe) frame.reference_keyframe = reference_keyframe_;
  record(frame);
  temporal_points_.clear();
  last_frame_ = std::move(frame);
  return state_;
}

void Tracker::initialize_stereo(Frame& frame) {
  const map::Measurements& m = frame.m();
  int stereo_points = 0;
  for (float z : m.depth) stereo_points += z > 0.0f ? 1 : 0;
  if (stereo_points < options_.min_initial_stereo_points) return;

  frame.set_pose(last_known_T_cw_.value_or(SE3()));
  map::KeyFrame* kf =
      map_.create_keyframe(frame.id, frame.timestamp, frame.T_cw, frame.measurements, &rig_);
  kf->set_origin();
  for (std::size_t i = 0; i < m.size(); ++i) {
    const std::optional<Vec3> p = kf->unproject_stereo(i);
    if (!p) continue;
    map::MapPoint* mp = map_.create_map_point(*p, kf);
    mp->add_observation(kf, i);
    kf->add_map_point(mp, i);
    mp->update_descriptor();
    mp->update_normal_and_depth();
    frame.map_points[i] = mp;
  }
  spdlog::info("frame {}: new map with {} points", frame.id, map_.map_point_count());
  ++maps_started_;
  mapper_.insert_keyframe(kf);
  frame.reference_keyframe = kf;
  reference_keyframe_ = kf;
  last_keyframe_ = kf;
  last_keyframe_frame_id_ = frame.id;
  local_keyframes_ = {kf};
  local_points_ = map_.map_points();
  state_ = TrackingState::kOk;
}

void Tracker::start_new_map(Frame& frame) {
  // A new map is a new connected component anchored at the last known pose, so the written
  // trajectory stays in one world frame; old keyframes remain for relocalisation.
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  state_ = TrackingState::kNotInitialized;
  initialize_stereo(frame);
}

void Tracker::replace_bad_points(Frame& frame) const {
  for (map::MapPoint*& mp : frame.map_points) {
    if (!mp) continue;
    if (map::MapPoint* replacement = mp->replaced_by()) {
      while (replacement->replaced_by()) replacement = replacement->replaced_by();
      mp = replacement->is_bad() ? nullptr : replacement;
    } else if (mp->is_bad()) {
      mp = nullptr;
    }
  }
}

bool Tracker::track_reference_keyframe(Frame& frame) {
  // Without a vocabulary, the reference keyframe's points are matched by descriptor alone.
  map::KeyFrame& kf = *reference_keyframe_;
  std::vector<std::size_t> kf_index;
  for (std::size_t i = 0; i < kf.keypoint_count(); ++i)
    if (kf.map_point(i) && !kf.map_point(i)->is_bad()) kf_index.push_back(i);
  if (kf_index.size() < 15) return false;
  cv::Mat query(static_cast<int>(kf_index.size()), 32, CV_8U);
  for (std::size_t j = 0; j < kf_index.size(); ++j)
    kf.measurements()
        .descriptors.row(static_cast<int>(kf_index[j]))
        .copyTo(query.row(static_cast<int>(j)));
  match::BruteForceOptions options;
  options.max_distance = match::kThresholdLow;
  options.nn_ratio = 0.7f;
  options.cross_check = false;
  const std::vector<match::Match> matches =
      match::match_brute_force(query, frame.m().descriptors, options);
  if (matches.size() < 15) return false;

  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  for (const match::Match& m : matches)
    frame.map_points[static_cast<std::size_t>(m.train)] =
        kf.map_point(kf_index[static_cast<std::size_t>(m.query)]);
  frame.set_pose(last_frame_.has_pose ? last_frame_.T_cw : kf.T_cw());
  optimize_frame_pose(frame, rig_);
  return frame.discard_outliers() >= 10;
}

void Tracker::add_temporal_points(Frame& last) {
  // ORB-SLAM's UpdateLastFrame: close stereo points of the last frame that have no map point
  // become short-lived points, so the motion model has enough to work with between keyframes.
  if (!rig_.stereo || last.id == last_keyframe_frame_id_ || !last.has_pose) return;
  const SE3 T_wc = last.T_cw.inverse();
  const map::Measurements& m = last.m();
  const PinholeIntrinsics& k = rig_.camera.intrinsics();
  int points = 0;
  for (std::size_t i : keypoints_by_depth(m)) {
    const float z = m.depth[i];
    if (!last.map_points[i] || last.map_points[i]->observation_count() < 1) {
      const feature::OrbKeypoint& kp = m.keypoints_un[i];
      const Vec3 p = T_wc * Vec3((kp.x - k.cx) * z / k.fx, (kp.y - k.cy) * z / k.fy, z);
      temporal_points_.push_back(std::make_unique<map::MapPoint>(0, p, nullptr, &map_));
      last.map_points[i] = temporal_points_.back().get();
    }
    ++points;
    if (z > rig_.th_depth && points > kMinNewStereoPoints) break;
  }
}

bool Tracker::track_with_motion_model(Frame& frame) {
  add_temporal_points(last_frame_);
  frame.set_pose(*velocity_ * last_frame_.T_cw);
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  const float radius = rig_.stereo ? 7.0f : 15.0f;
  int matches = search_from_last_frame(frame, last_frame_, rig_, radius);
  if (matches < 20) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = search_from_last_frame(frame, last_frame_, rig_, 2.0f * radius);
  }
  if (matches < 20) return false;
  optimize_frame_pose(frame, rig_);
  // Temporal points must not leak into the map or the next frame.
  for (map::MapPoint*& mp : frame.map_points)
    if (mp && mp->observation_count() == 0 && mp->reference_keyframe() == nullptr) mp = nullptr;
  return frame.discard_outliers() >= 10;
}

void Tracker::update_local_map(const Frame& frame) {
  // Keyframes voting with the frame's points, then their best neighbours, children and parents.
  std::map<map::KeyFrame*, int, map::KeyFrameIdLess> votes;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    map::MapPoint* mp = frame.map_points[i];
    if (!mp || mp->is_bad()) continue;
    for (const auto& [kf, index] : mp->observations()) ++votes[kf];
  }
  local_keyframes_.clear();
  map::KeyFrame* best = nullptr;
  int best_votes = 0;
  for (const auto& [kf, count] : votes) {
    if (kf->is_bad()) continue;
    if (count > best_votes) {
      best_votes = count;
      best = kf;
    }
    local_keyframes_.push_back(kf);
    kf->track_reference_for_frame = frame.id;
  }
  const std::size_t voted = local_keyframes_.size();
  for (std::size_t j = 0; j < voted && local_keyframes_.size() < kMaxLocalKeyframes; ++j) {
    map::KeyFrame* kf = local_keyframes_[j];
    auto add = [&](map::KeyFrame* other) {
      if (!other || other->is_bad() || other->track_reference_for_frame == frame.id) return false;
      other->track_reference_for_frame = frame.id;
      local_keyframes_.push_back(other);
      return true;
    };
    for (map::KeyFrame* neighbour : kf->best_covisibles(10))
      if (add(neighbour)) break;
    for (map::KeyFrame* child : kf->children())
      if (add(child)) break;
    add(kf->parent());
  }
  if (best) reference_keyframe_ = best;

  local_points_.clear();
  for (map::KeyFrame* kf : local_keyframes_)
    for (map::MapPoint* mp : kf->map_points()) {
      if (!mp || mp->is_bad() || mp->track_reference_for_frame == frame.id) continue;
      mp->track_reference_for_frame = frame.id;
      local_points_.push_back(mp);
    }
}

bool Tracker::track_local_map(Frame& frame) {
  update_local_map(frame);
  for (map::MapPoint* mp : frame.map_points) {
    if (!mp || mp->is_bad()) continue;
    mp->increase_visible();
    mp->last_seen_frame = frame.id;
    mp->track_in_view = false;
  }
  int to_match = 0;
  for (map::MapPoint* mp : local_points_) {
    if (mp->last_seen_frame == frame.id) continue;
    if (is_in_frustum(*mp, frame, rig_, 0.5)) {
      mp->increase_visible();
      ++to_match;
    }
  }
  if (to_match > 0) {
    const bool recently_relocalized = frame.id < last_relocalization_frame_id_ + 2;
    search_local_points(frame, local_points_, rig_, recently_relocalized ? 5.0f : 1.0f);
  }
  optimize_frame_pose(frame, rig_);

  inlier_matches_ = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    map::MapPoint* mp = frame.map_points[i];
    if (!mp) continue;
    if (!frame.outlier[i]) {
      mp->increase_found();
      if (mp->observation_count() > 0) ++inlier_matches_;
    }
  }
  const int needed =
      frame.id < last_relocalization_frame_id_ + options_.max_frames_between_keyframes
          ? kMinInliersAfterRelocalization
          : kMinTrackedInliers;
  return inlier_matches_ >= needed;
}

bool Tracker::relocalize(Frame& frame) {
  std::vector<map::KeyFrame*> candidates = map_.keyframes();
  std::reverse(candidates.begin(), candidates.end());  // most recent first
  if (static_cast<int>(candidates.size()) > options_.relocalization_candidates)
    candidates.resize(static_cast<std::size_t>(options_.relocalization_candidates));
  if (!relocalizer_.relocalize(frame, candidates)) return false;
  spdlog::info("frame {}: relocalised", frame.id);
  last_relocalization_frame_id_ = frame.id;
  return true;
}

bool Tracker::need_new_keyframe(const Frame& frame) const {
  const std::size_t keyframes = map_.keyframe_count();
  if (frame.id < last_relocalization_frame_id_ +
                     static_cast<std::size_t>(options_.max_frames_between_keyframes) &&
      keyframes > static_cast<std::size_t>(options_.max_frames_between_keyframes))
    return false;

  const int min_observations = keyframes <= 2 ? 2 : 3;
  const int reference_matches = reference_keyframe_->tracked_map_points(min_observations);
  const bool mapper_idle = mapper_.is_idle();

  int tracked_close = 0, untracked_close = 0;
  if (rig_.stereo) {
    for (std::size_t i = 0; i < frame.size(); ++i) {
      const float z = frame.m().depth[i];
      if (z <= 0.0f || z >= rig_.th_depth) continue;
      if (frame.map_points[i] && !frame.outlier[i]) {
        ++tracked_close;
      } else {
        ++untracked_close;
      }
    }
  }
  const bool need_close = tracked_close < 100 && untracked_close > 70;
  double ratio = keyframes < 2 ? 0.4 : 0.75;
  if (!rig_.stereo) ratio = 0.9;

  const std::size_t since = frame.id - last_keyframe_frame_id_;
  const bool c1a = since >= static_cast<std::size_t>(options_.max_frames_between_keyframes);
  const bool c1b =
      since >= static_cast<std::size_t>(options_.min_frames_between_keyframes) && mapper_idle;
  const bool c1c = rig_.stereo && (inlier_matches_ < reference_matches * 0.25 || need_close);
  const bool c2 =
      (inlier_matches_ < reference_matches * ratio || need_close) && inlier_matches_ > 15;
  spdlog::debug("frame {}: inliers {} reference {} close tracked {} untracked {}", frame.id,
                inlier_matches_, reference_matches, tracked_close, untracked_close);
  if (!((c1a || c1b || c1c) && c2)) return false;
  if (mapper_idle) return true;
  mapper_.interrupt_bundle_adjustment();
  return rig_.stereo && mapper_.queued_keyframes() < 3;
}

void Tracker::create_keyframe(Frame& frame) {
  map::KeyFrame* kf =
      map_.create_keyframe(frame.id, frame.timestamp, frame.T_cw, frame.measurements, &rig_);
  for (std::size_t i = 0; i < frame.size(); ++i)
    if (frame.map_points[i] && !frame.map_points[i]->is_bad())
      kf->add_map_point(frame.map_points[i], i);

  if (rig_.stereo) {
    int points = 0;
    for (std::size_t i : keypoints_by_depth(frame.m())) {
      map::MapPoint* existing = frame.map_points[i];
      if (!existing || existing->observation_count() < 1) {
        const std::optional<Vec3> p = kf->unproject_stereo(i);
        map::MapPoint* mp = map_.create_map_point(*p, kf);
        mp->add_observation(kf, i);
        kf->add_map_point(mp, i);
        mp->update_descriptor();
        mp->update_normal_and_depth();
        frame.map_points[i] = mp;
        frame.outlier[i] = 0;
      }
      ++points;
      if (frame.m().depth[i] > rig_.th_depth && points > kMinNewStereoPoints) break;
    }
  }
  reference_keyframe_ = kf;
  frame.reference_keyframe = kf;
  last_keyframe_ = kf;
  last_keyframe_frame_id_ = frame.id;
  mapper_.insert_keyframe(kf);
}

void Tracker::record(const Frame& frame) {
  FrameRecord r;
  r.timestamp = frame.timestamp;
  if (frame.has_pose && state_ == TrackingState::kOk && frame.reference_keyframe) {
    r.reference = frame.reference_keyframe;
    r.T_cr = frame.T_cw * frame.reference_keyframe->T_wc();
  }
  records_.push_back(r);
}

}  // namespace sbaslam::tracking
