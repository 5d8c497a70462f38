#include "sbaslam/tracking/tracker.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <mutex>

#include "sbaslam/core/timing.h"
#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"
#include "sbaslam/tracking/frame_pose.h"
#include "sbaslam/tracking/projection.h"

namespace sbaslam::tracking {
namespace {

constexpr int kMaxLocalKeyframes = 80;
constexpr int kMinTrackedInliers = 30;
constexpr int kMinFrameToFrameInliers = 10;
constexpr int kMinInliersAfterRelocalization = 50;
// Place-recognition candidates tried per frame near a PosePrior.
constexpr std::size_t kMaxCandidatesNearPrior = 3;
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

// The median depth of the frame's map points in its camera (0 without any in front of it).
double median_point_depth(const Frame& frame) {
  std::vector<double> depths;
  for (const map::MapPoint* mp : frame.map_points) {
    if (!mp || mp->is_bad()) continue;
    const double z = (frame.T_cw * mp->position()).z();
    if (z > 0.0) depths.push_back(z);
  }
  if (depths.empty()) return 0.0;
  const auto middle = depths.begin() + static_cast<long>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return *middle;
}

}  // namespace

Tracker::Tracker(map::Map& map, const map::CameraRig& rig, KeyframeSink& mapper,
                 TrackerOptions options, std::uint64_t seed)
    : map_(map),
      rig_(rig),
      mapper_(mapper),
      options_(options),
      relocalizer_(rig, seed),
      seed_(seed) {
  if (!rig_.stereo)
    two_view_ = std::make_unique<TwoViewInitializer>(rig_.camera.intrinsics(), rig_.levels);
}

TrackingState Tracker::track(Frame frame) {
  const Stopwatch lock_wait;
  std::unique_lock<std::mutex> lock = map_.lock_for_tracking();
  timings_.map_lock_wait_ms.push_back(lock_wait.elapsed_ms());
  follow_map_correction();
  if (state_ == TrackingState::kNotInitialized) {
    if (rig_.stereo) {
      initialize_stereo(frame);
    } else {
      initialize_monocular(frame);
    }
    record(frame);
    last_frame_ = std::move(frame);
    if (!rig_.stereo) last_frame_depth_ = median_point_depth(last_frame_);
    predict_point_depths();
    return state_;
  }

  bool ok = false;
  bool by_odometry = false;
  // Localization-only stereo, out of the map or lost: odometry and relocalisation in one step.
  const bool beyond_map =
      options_.localization_only && rig_.stereo && (state_ != TrackingState::kOk || odometry_);
  const Stopwatch frame_to_frame;
  if (beyond_map) {
    ok = track_beyond_map(frame, by_odometry);
  } else if (state_ == TrackingState::kOk) {
    replace_bad_points(last_frame_);
    ok = track_frame_to_frame(frame);
  } else {
    ok = relocalize(frame);
  }
  if (!frame.reference_keyframe) frame.reference_keyframe = reference_keyframe_;
  const Stopwatch local_map;
  if (ok && !beyond_map) {
    timings_.frame_to_frame_ms.push_back(frame_to_frame.elapsed_ms());
    ok = track_local_map(frame);
    timings_.local_map_ms.push_back(local_map.elapsed_ms());
  }
  if (!ok && state_ == TrackingState::kOk && !odometry_) {
    // Lost in this frame: try to relocalise at once before giving up on the map.
    spdlog::warn("frame {}: tracking lost", frame.id);
    ok = options_.localization_only && rig_.stereo ? track_beyond_map(frame, by_odometry)
                                                   : relocalize(frame) && track_local_map(frame);
  }
  if (ok && by_odometry != odometry_)
    spdlog::info(by_odometry ? "frame {}: out of the map, visual odometry until it relocalises"
                             : "frame {}: back in the map",
                 frame.id);

  if (ok) {
    odometry_ = by_odometry;
    const double moved =
        last_known_T_cw_
            ? (frame.T_cw.inverse().translation() - last_known_T_cw_->inverse().translation())
                  .norm()
            : 0.0;
    last_step_ =
        last_known_T_cw_ ? moved / static_cast<double>(frame.id - last_pose_frame_id_) : 0.0;
    if (by_odometry) {
      ++odometry_frames_;
      odometry_path_ += moved;
    } else {
      odometry_path_ = 0.0;
    }
    state_ = TrackingState::kOk;
    velocity_ = last_frame_.has_pose ? std::optional<SE3>(frame.T_cw * last_frame_.T_cw.inverse())
                                     : std::nullopt;
    last_known_T_cw_ = frame.T_cw;
    last_pose_frame_id_ = frame.id;
    const Stopwatch keyframe;
    const KeyframeNeed need = need_new_keyframe(frame);
    keyframe_deferred_ = need == KeyframeNeed::kMappingBusy;
    if (need == KeyframeNeed::kInsert) create_keyframe(frame);
    timings_.keyframe_ms.push_back(keyframe.elapsed_ms());
    // Outliers stay in the new keyframe for BA to judge, but must not steer the next frame.
    frame.discard_outliers();
  } else {
    if (state_ != TrackingState::kLost) lost_since_frame_id_ = frame.id;
    if (options_.localization_only && last_frame_.has_pose) {
      odometry_anchor_ = last_frame_;
      drop_temporal_points(*odometry_anchor_);
    }
    state_ = TrackingState::kLost;
    odometry_ = false;
    frame.has_pose = false;
    velocity_.reset();
    if (options_.localization_only) {
      // The map is not ours to extend: the next frame tries to relocalise in it again.
    } else if (rig_.stereo) {
      start_new_map(frame);
    } else if (frame.id >=
               lost_since_frame_id_ + static_cast<std::size_t>(options_.max_lost_frames)) {
      // A monocular map cannot restart from one frame: a new two-view initialisation begins.
      spdlog::warn("frame {}: lost for {} frames, initialising a new map", frame.id,
                   frame.id - lost_since_frame_id_);
      state_ = TrackingState::kNotInitialized;
      initial_frame_.reset();
    }
  }
  if (!frame.reference_keyframe) frame.reference_keyframe = reference_keyframe_;
  record(frame);
  drop_temporal_points(frame);
  temporal_points_.clear();
  last_frame_ = std::move(frame);
  if (!rig_.stereo) last_frame_depth_ = median_point_depth(last_frame_);
  predict_point_depths();
  return state_;
}

void Tracker::start_in_loaded_map(map::KeyFrame* reference, std::size_t first_frame_id) {
  first_run_keyframe_id_ = map_.max_keyframe_id() + 1;
  state_ = TrackingState::kLost;
  reference_keyframe_ = reference;
  lost_since_frame_id_ = first_frame_id;
  initialization_status_.clear();
}

void Tracker::follow_map_correction() {
  const std::size_t index = map_.big_change_index();
  if (index == seen_big_change_) return;
  seen_big_change_ = index;
  // ORB-SLAM's UpdateLastFrame: after a loop correction the last frame's pose is stale, so the
  // motion model would search the corrected map from the old place; it moves with its reference.
  if (!last_frame_.has_pose || records_.empty() || !records_.back().reference) return;
  const map::KeyFrame* kf = records_.back().reference;
  SE3 T_cr = records_.back().T_cr;
  while (kf->is_bad() && kf->parent()) {
    T_cr = T_cr * kf->T_cp();
    kf = kf->parent();
  }
  last_frame_.set_pose(T_cr * kf->T_cw());
  if (!rig_.stereo) follow_map_rescaling(T_cr, *kf);
  last_known_T_cw_ = last_frame_.T_cw;
}

void Tracker::follow_map_rescaling(const SE3& T_cr, const map::KeyFrame& reference) {
  // A monocular correction (a loop's Sim3, a merge into a map of another scale) rescales the map
  // around the frame too. The frame's offset from its reference and the motion model's step are
  // lengths of the old scale: unscaled, the next frame is searched for where the old step puts it.
  // The change of the frame's median point depth gives the new scale; the offset's own error
  // moves that depth a little, so it is measured again once the offset is rescaled.
  if (last_frame_depth_ <= 0.0) return;
  double scale = 1.0;
  for (int pass = 0; pass < 2; ++pass) {
    const double depth = median_point_depth(last_frame_);
    if (depth <= 0.0) return;
    scale = depth / last_frame_depth_;
    last_frame_.set_pose(SE3(T_cr.so3(), scale * T_cr.translation()) * reference.T_cw());
  }
  if (velocity_) velocity_ = SE3(velocity_->so3(), velocity_->translation() * scale);
  last_frame_depth_ = median_point_depth(last_frame_);
}

bool Tracker::insert_deferred_keyframe() {
  if (!keyframe_deferred_) return false;
  keyframe_deferred_ = false;
  std::unique_lock<std::mutex> lock = map_.lock_for_tracking();
  if (state_ != TrackingState::kOk || !last_frame_.has_pose) return false;
  // A loop closure or a merge may have moved the map while the frame waited: a keyframe made at
  // its old pose sat in the old world (a merged monocular run lost the next frame and mapped
  // from the stray keyframe).
  follow_map_correction();
  // Mapping may have culled or fused the frame's points while it waited.
  replace_bad_points(last_frame_);
  if (need_new_keyframe(last_frame_) != KeyframeNeed::kInsert) return false;
  create_keyframe(last_frame_);
  records_.pop_back();  // the frame's pose is now its own keyframe's
  record(last_frame_);
  return true;
}

void Tracker::predict_point_depths() {
  std::vector<saliency::DepthSample>& samples = predicted_depths_;
  samples.clear();
  if (rig_.stereo || state_ != TrackingState::kOk || !last_frame_.has_pose) return;
  const SE3 T_cw = velocity_ ? *velocity_ * last_frame_.T_cw : last_frame_.T_cw;
  for (const map::MapPoint* mp : last_frame_.map_points) {
    if (!mp || mp->is_bad()) continue;
    const Vec3 p = T_cw * mp->position();
    if (p.z() <= 0.0) continue;
    const Vec2 uv = rig_.camera.project_distorted(p);
    if (uv.x() < 0.0 || uv.y() < 0.0 || uv.x() >= rig_.width || uv.y() >= rig_.height) continue;
    samples.push_back(
        {static_cast<float>(uv.x()), static_cast<float>(uv.y()), static_cast<float>(p.z())});
  }
}

void Tracker::initialize_stereo(Frame& frame) {
  const map::Measurements& m = frame.m();
  int stereo_points = 0;
  for (float z : m.depth) stereo_points += z > 0.0f ? 1 : 0;
  if (stereo_points < options_.min_initial_stereo_points) return;

  frame.set_pose(last_known_T_cw_.value_or(SE3()));
  map::KeyFrame* kf = map_.create_keyframe(frame.id, frame.timestamp, frame.T_cw,
                                           frame.measurements, &rig_, map_.new_map_id());
  kf->set_origin();
  local_points_.clear();
  for (std::size_t i = 0; i < m.size(); ++i) {
    const std::optional<Vec3> p = kf->unproject_stereo(i);
    if (!p) continue;
    map::MapPoint* mp = map_.create_map_point(*p, kf);
    mp->add_observation(kf, i);
    kf->add_map_point(mp, i);
    mp->update_descriptor();
    mp->update_normal_and_depth();
    frame.map_points[i] = mp;
    local_points_.push_back(mp);
  }
  spdlog::info("frame {}: new map with {} points", frame.id, local_points_.size());
  ++maps_started_;
  mapper_.insert_keyframe(kf);
  frame.reference_keyframe = kf;
  reference_keyframe_ = kf;
  last_keyframe_ = kf;
  last_keyframe_frame_id_ = frame.id;
  local_keyframes_ = {kf};
  state_ = TrackingState::kOk;
}

void Tracker::initialize_monocular(Frame& frame) {
  // ORB-SLAM's MonocularInitialization: keep a first frame, match later frames against it in a
  // window, and accept a two-view reconstruction only when it is unambiguous with enough parallax.
  constexpr int kMinKeypoints = 100;
  const bool stale =
      initial_frame_ &&
      frame.id > initial_frame_->id + static_cast<std::size_t>(options_.max_initialization_gap);
  if (!initial_frame_ || stale || frame.size() <= kMinKeypoints) {
    if (frame.size() > kMinKeypoints) {
      initial_frame_ = frame;
      initial_search_keypoints_ = frame.m().keypoints_un;
    } else {
      initial_frame_.reset();
    }
    // Keep the last attempt's reason (e.g. insufficient parallax) when a stale first frame is
    // replaced; only the very first frame has nothing better to report.
    if (!stale) initialization_status_ = "not initialised: waiting for a second view";
    return;
  }
  // As ORB-SLAM's mvbPrevMatched, the search window follows each keypoint to where it was last
  // matched, so matches survive fast forward motion until the baseline is large enough.
  // Unlike ORB-SLAM, every octave takes part (each searched within its own octave): with the
  // normal feature budget, level 0 alone loses too many matches under fast forward motion.
  match::WindowOptions window;
  window.level0_only = false;
  const std::vector<match::Match> matches = match::match_in_window(
      initial_search_keypoints_, initial_frame_->m().descriptors, frame_view(frame, rig_), window);
  if (static_cast<int>(matches.size()) < two_view_->options().min_matches) {
    initialization_status_ = fmt::format("not initialised: too few matches ({})", matches.size());
    spdlog::debug("frame {}: {}", frame.id, initialization_status_);
    initial_frame_ = frame;
    initial_search_keypoints_ = frame.m().keypoints_un;
    return;
  }
  for (const match::Match& m : matches) {
    const feature::OrbKeypoint& found = frame.m().keypoints_un[static_cast<std::size_t>(m.train)];
    initial_search_keypoints_[static_cast<std::size_t>(m.query)].x = found.x;
    initial_search_keypoints_[static_cast<std::size_t>(m.query)].y = found.y;
  }
  const TwoViewResult result = two_view_->initialize(
      initial_frame_->m().keypoints_un, frame.m().keypoints_un, matches, seed_ + frame.id);
  if (!result.ok()) {
    initialization_status_ = result.message;
    spdlog::debug("frame {}: {}", frame.id, result.message);
    return;
  }
  if (create_monocular_map(*initial_frame_, frame, matches, result)) {
    initialization_status_.clear();
    // The first frame of the pair gets its pose now; its record was written without one.
    FrameRecord& first = records_[initial_frame_->id];
    first.reference = initial_frame_->reference_keyframe;
    first.T_cr = SE3();
  }
  initial_frame_.reset();
}

bool Tracker::create_monocular_map(Frame& first, Frame& second,
                                   const std::vector<match::Match>& matches,
                                   const TwoViewResult& result) {
  const SE3 origin = last_known_T_cw_.value_or(SE3());
  first.set_pose(origin);
  second.set_pose(result.T21() * origin);
  const std::size_t map_id = map_.new_map_id();
  map::KeyFrame* kf1 = map_.create_keyframe(first.id, first.timestamp, first.T_cw,
                                            first.measurements, &rig_, map_id);
  map::KeyFrame* kf2 = map_.create_keyframe(second.id, second.timestamp, second.T_cw,
                                            second.measurements, &rig_, map_id);
  kf1->set_origin();
  std::vector<map::MapPoint*> points;
  const SE3 T_wc1 = first.T_cw.inverse();
  for (std::size_t i = 0; i < result.points.size(); ++i) {
    if (!result.triangulated[i]) continue;
    const match::Match& m = matches[i];
    map::MapPoint* mp = map_.create_map_point(T_wc1 * result.points[i], kf1);
    mp->add_observation(kf1, static_cast<std::size_t>(m.query));
    mp->add_observation(kf2, static_cast<std::size_t>(m.train));
    kf1->add_map_point(mp, static_cast<std::size_t>(m.query));
    kf2->add_map_point(mp, static_cast<std::size_t>(m.train));
    mp->update_descriptor();
    mp->update_normal_and_depth();
    points.push_back(mp);
  }
  kf1->update_connections();
  kf2->update_connections();

  optimize::MapBundleAdjustment ba =
      optimize::build_bundle_adjustment({kf1, kf2}, rig_, options_.map_ba_weighting);
  optimize::BundleAdjusterOptions ba_options;
  ba_options.iterations = 20;
  ba_options.refine_iterations = 0;
  ba_options.weight_scale = options_.map_ba_weight_scale;
  optimize::solve_map_bundle_adjustment(ba, ba_options);
  optimize::apply_map_bundle_adjustment(ba);

  // Median scene depth of the first keyframe becomes 1 (ORB-SLAM's scale convention).
  const double median_depth = kf1->scene_depth_quantile(0.5);
  if (median_depth <= 0.0 || kf2->tracked_map_points(1) < 50) {
    spdlog::warn("frame {}: two-view map rejected after BA (median depth {:.3f}, {} points)",
                 second.id, median_depth, kf2->tracked_map_points(1));
    for (map::MapPoint* mp : points) mp->set_bad();
    map_.discard_keyframe(kf2);
    map_.discard_keyframe(kf1);
    initialization_status_ = "not initialised: two-view map rejected after bundle adjustment";
    return false;
  }
  const double scale = 1.0 / median_depth;
  const SE3 T_c2c1 = kf2->T_cw() * kf1->T_wc();
  kf2->set_pose(SE3(T_c2c1.so3(), scale * T_c2c1.translation()) * kf1->T_cw());
  const SE3 T_wc1_final = kf1->T_wc();
  for (map::MapPoint* mp : points) {
    if (mp->is_bad()) continue;
    const Vec3 p_c1 = kf1->T_cw() * mp->position();
    mp->set_position(T_wc1_final * (scale * p_c1));
    mp->update_normal_and_depth();
  }

  std::fill(second.map_points.begin(), second.map_points.end(), nullptr);
  for (std::size_t i = 0; i < kf2->keypoint_count(); ++i)
    if (kf2->map_point(i) && !kf2->map_point(i)->is_bad()) second.map_points[i] = kf2->map_point(i);
  second.set_pose(kf2->T_cw());
  first.reference_keyframe = kf1;
  second.reference_keyframe = kf2;
  mapper_.insert_keyframe(kf1);
  mapper_.insert_keyframe(kf2);
  reference_keyframe_ = kf2;
  last_keyframe_ = kf2;
  last_keyframe_frame_id_ = second.id;
  last_known_T_cw_ = second.T_cw;
  ++maps_started_;
  state_ = TrackingState::kOk;
  spdlog::info("frame {}: new monocular map from frames {} and {}, {} points ({})", second.id,
               first.id, second.id, points.size(), result.message);
  return true;
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

bool Tracker::track_frame_to_frame(Frame& frame) {
  if (!velocity_ || frame.id < last_relocalization_frame_id_ + 2) {
    const int inliers = track_reference_keyframe(frame);
    return inliers >= kMinFrameToFrameInliers &&
           frame.discard_outliers() >= kMinFrameToFrameInliers;
  }
  // The constant-velocity guess fails when the motion changes abruptly (a turn begins or ends):
  // the windowed search then finds only a few, partly wrong matches and the pose settles on a wrong
  // optimum. When the motion model keeps much less support than the last frame had, the reference
  // keyframe is matched by descriptor, independent of the guess, and the better-supported pose
  // wins.
  const int last_support = last_frame_.matched_count();
  Frame by_motion = frame;
  const int motion_inliers = track_with_motion_model(by_motion).map_points;
  if (motion_inliers < kMinFrameToFrameInliers ||
      motion_inliers < options_.weak_motion_model_ratio * last_support) {
    ++weak_motion_model_frames_;
    Frame by_reference = frame;
    const int reference_inliers = track_reference_keyframe(by_reference);
    spdlog::debug("frame {}: weak motion model ({} inliers, last frame {}), reference keyframe {}",
                  frame.id, motion_inliers, last_support, reference_inliers);
    if (reference_inliers > motion_inliers) {
      frame = std::move(by_reference);
      return reference_inliers >= kMinFrameToFrameInliers &&
             frame.discard_outliers() >= kMinFrameToFrameInliers;
    }
  }
  frame = std::move(by_motion);
  return motion_inliers >= kMinFrameToFrameInliers &&
         frame.discard_outliers() >= kMinFrameToFrameInliers;
}

int Tracker::track_reference_keyframe(Frame& frame) {
  map::KeyFrame& kf = *reference_keyframe_;
  const std::vector<PointMatch> matches = match_keyframe_points_by_descriptor(kf, frame, 0.7f);
  if (matches.size() < 15) return 0;
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  for (const PointMatch& m : matches) frame.map_points[m.keypoint] = m.point;
  frame.set_pose(last_frame_.has_pose ? last_frame_.T_cw : kf.T_cw());
  return optimize_frame_pose(frame, rig_);
}

void Tracker::add_temporal_points(Frame& last, int min_points) {
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
    if (z > rig_.th_depth && points > min_points) break;
  }
}

Tracker::MotionModelInliers Tracker::track_with_motion_model(Frame& frame,
                                                             int min_temporal_points) {
  add_temporal_points(last_frame_, min_temporal_points);
  frame.set_pose(*velocity_ * last_frame_.T_cw);
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  const float radius = options_.motion_model_radius;
  int matches = search_from_last_frame(frame, last_frame_, rig_, radius);
  if (matches < 20) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = search_from_last_frame(frame, last_frame_, rig_, 2.0f * radius);
  }
  if (matches < 20) return {};
  MotionModelInliers inliers;
  inliers.all = optimize_frame_pose(frame, rig_);
  // Temporal points must not leak into the map, nor count as map support. In localization mode
  // they stay for the local map's pose optimisation, as in ORB-SLAM: near the map's edge its few
  // far points alone left the pose 0.2-1.8 m off.
  for (std::size_t i = 0; i < frame.size(); ++i) {
    map::MapPoint*& mp = frame.map_points[i];
    if (is_temporal_point(mp)) {
      if (!options_.localization_only) mp = nullptr;
    } else if (mp && !frame.outlier[i]) {
      ++inliers.map_points;
    }
  }
  return inliers;
}

void Tracker::update_local_map(const Frame& frame) {
  // Keyframes voting with the frame's points, then their best neighbours, children and parents.
  // Counted on the keyframes themselves: a map keyed by keyframe cost a tree search per
  // observation, several thousand per frame.
  voting_keyframes_.clear();
  const std::size_t round = ++vote_rounds_;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    map::MapPoint* mp = frame.map_points[i];
    if (!mp || mp->is_bad()) continue;
    for (const auto& [kf, index] : mp->observations()) {
      if (kf->track_votes_round != round) {
        kf->track_votes_round = round;
        kf->track_votes = 0;
        voting_keyframes_.push_back(kf);
      }
      ++kf->track_votes;
    }
  }
  // By id, as before: the first of equally voted keyframes becomes the reference.
  std::sort(voting_keyframes_.begin(), voting_keyframes_.end(), map::KeyFrameIdLess());
  local_keyframes_.clear();
  map::KeyFrame* best = nullptr;
  int best_votes = 0;
  for (map::KeyFrame* kf : voting_keyframes_) {
    if (kf->is_bad()) continue;
    if (kf->track_votes > best_votes) {
      best_votes = kf->track_votes;
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

bool Tracker::relocalize(Frame& frame, const std::optional<PosePrior>& prior) {
  const Stopwatch attempt;
  const bool found = relocalize_in_tracked_map(frame, prior);
  timings_.relocalization_ms.push_back(attempt.elapsed_ms());
  if (!found) return false;
  spdlog::info("frame {}: relocalised", frame.id);
  last_relocalization_frame_id_ = frame.id;
  ++relocalizations_;
  return true;
}

bool Tracker::relocalize_in_tracked_map(Frame& frame, const std::optional<PosePrior>& prior) {
  // Only the map the frame was tracked in: another map has a world (and, monocular, a scale) of
  // its own, and joining maps is loop closing's merge (ORB-SLAM3 relocalises in the active map).
  if (!reference_keyframe_) return false;
  const std::size_t map_id = reference_keyframe_->map_id();
  std::vector<map::KeyFrame*> candidates;
  if (place_recognition_) candidates = place_recognition_(frame, map_id);
  if (prior) {
    keep_nearest(candidates, *prior, kMaxCandidatesNearPrior);
    return relocalizer_.relocalize(frame, candidates,
                                   [&prior](const SE3& T_cw) { return within(*prior, T_cw); });
  }
  // The newest keyframes may not be filed yet (loop closing files them after its check). A loaded
  // map was filed whole when it was loaded: its newest keyframes are not tried for that reason
  // (they had put the first frame of a run that began 44 m past the map's end 51 m off, their
  // look-alike facades fitting; docs/RESULTS.md, "Session 35").
  const std::vector<map::KeyFrame*> keyframes = map_.keyframes();
  int recent = 0;
  for (auto it = keyframes.rbegin();
       it != keyframes.rend() && recent < options_.relocalization_candidates; ++it) {
    if ((*it)->map_id() != map_id || (place_recognition_ && (*it)->id() < first_run_keyframe_id_))
      continue;
    ++recent;
    if (std::find(candidates.begin(), candidates.end(), *it) == candidates.end())
      candidates.push_back(*it);
  }
  return relocalizer_.relocalize(frame, candidates);
}

Tracker::KeyframeNeed Tracker::need_new_keyframe(const Frame& frame) const {
  if (options_.localization_only) return KeyframeNeed::kNone;
  // Counted in the tracked map only: a map started after a loss is young whatever came before
  // (its points have two observations, and the old maps' count asked for three, so it never
  // wanted a keyframe and was lost again within frames).
  const std::size_t keyframes = map_.keyframe_count_in_map(reference_keyframe_->map_id());
  if (frame.id < last_relocalization_frame_id_ +
                     static_cast<std::size_t>(options_.max_frames_between_keyframes) &&
      keyframes > static_cast<std::size_t>(options_.max_frames_between_keyframes))
    return KeyframeNeed::kNone;

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
  // ORB-SLAM's rule, plus one for fast rotations in small rooms: most close stereo points are new
  // to the map although enough are tracked, so the view is turning away from the map.
  const bool need_close =
      (tracked_close < 100 && untracked_close > 70) ||
      (untracked_close > options_.new_view_ratio * tracked_close && untracked_close > 200);
  double ratio = keyframes < 2 ? 0.4 : 0.75;
  if (!rig_.stereo) ratio = 0.9;

  const std::size_t since = frame.id - last_keyframe_frame_id_;
  const bool c1a = since >= static_cast<std::size_t>(options_.max_frames_between_keyframes);
  // ORB-SLAM asks for mapping to be idle here; a frame that would qualify but for a busy mapper
  // is reported as deferred (see keyframe_deferred), so that offline playback can wait.
  const bool c1b = since >= static_cast<std::size_t>(options_.min_frames_between_keyframes);
  const bool c1c = rig_.stereo && (inlier_matches_ < reference_matches * 0.25 || need_close);
  const bool c2 =
      (inlier_matches_ < reference_matches * ratio || need_close) && inlier_matches_ > 15;
  spdlog::debug("frame {}: inliers {} reference {} close tracked {} untracked {}", frame.id,
                inlier_matches_, reference_matches, tracked_close, untracked_close);
  if (!((c1a || c1b || c1c) && c2)) return KeyframeNeed::kNone;
  spdlog::debug("frame {}: keyframe wanted (max frames {}, mapper idle {}, close points {})",
                frame.id, c1a, mapper_idle, need_close);
  if (mapper_idle) return KeyframeNeed::kInsert;
  if (!(c1a || c1c)) return KeyframeNeed::kMappingBusy;
  mapper_.interrupt_bundle_adjustment();
  if (rig_.stereo && mapper_.queued_keyframes() < 3) return KeyframeNeed::kInsert;
  return KeyframeNeed::kMappingBusy;
}

void Tracker::create_keyframe(Frame& frame) {
  map::KeyFrame* kf =
      map_.create_keyframe(frame.id, frame.timestamp, frame.T_cw, frame.measurements, &rig_,
                           reference_keyframe_->map_id());
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
