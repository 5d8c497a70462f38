#pragma once
// The tracking thread's per-frame step (ORB-SLAM's Tracking::Track, visual only): initialise the
// map from a stereo frame, track with the constant-velocity model (falling back to the reference
// keyframe), refine against the local map, decide on keyframes, and relocalise or start a new map
// after a loss. A run never aborts: loss is a state.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "sbaslam/map/map.h"
#include "sbaslam/optimize/map_bundle_adjustment.h"
#include "sbaslam/saliency/depth_correction.h"
#include "sbaslam/tracking/frame.h"
#include "sbaslam/tracking/keyframe_sink.h"
#include "sbaslam/tracking/pose_prior.h"
#include "sbaslam/tracking/relocalizer.h"
#include "sbaslam/tracking/two_view_initializer.h"

namespace sbaslam::tracking {

enum class TrackingState { kNotInitialized, kOk, kLost };

struct TrackerOptions {
  int min_frames_between_keyframes = 0;
  int max_frames_between_keyframes = 10;  // ORB-SLAM: the camera's fps
  int min_initial_stereo_points = 500;
  // Recent keyframes of the tracked map tried when lost, after those place recognition offers.
  int relocalization_candidates = 30;
  // Monocular: the first frame of a two-view attempt is replaced after this many frames without
  // success, and a lost monocular map is given up for a new one after this many frames.
  int max_initialization_gap = 30;
  int max_lost_frames = 10;
  // The motion model is weak when its inliers fall below this share of the last frame's matched
  // points (0.4 to 0.7 in steady driving, under 0.3 where a turn begins or ends).
  double weak_motion_model_ratio = 0.3;
  // Half-size, in pixels times the scale of the point's pyramid level, of the window in which the
  // motion model looks for each point of the last frame; twice that when it finds fewer than 20
  // matches. One value for both sensors: ORB-SLAM3 uses 15 for monocular but 7 for stereo. When
  // the rotation speeds up, the constant-velocity guess is off by the change of speed: in `room`'s
  // 90-degree turns (1.2 degrees per frame per frame, ~10 px), 7 px windows left the motion model
  // weak on 11 frames of each run, the poses of those frames put a 0.8 degree error into the map,
  // and the ATE was 3.7 cm (threaded median of 10; 1.5 cm with 15 px, docs/RESULTS.md session 14).
  float motion_model_radius = 15.0f;
  // A stereo keyframe is also needed when untracked close points outnumber the tracked ones by
  // this factor (see need_new_keyframe).
  double new_view_ratio = 2.0;
  // ORB-SLAM3's localization mode: frames are tracked in the map as it is (a loaded one), no
  // keyframe is made, and a lost frame relocalises in it instead of starting a new map.
  bool localization_only = false;
  // Localization-only stereo and RGB-D: once the map is out of view, visual odometry (the motion
  // model on the last frame's stereo points) keeps the pose, and every frame tries to relocalise
  // in the map. A relocalisation counts only within this distance of the odometry pose, in map
  // units: a base plus a share of the path driven on odometry since the map was lost from view
  // (its drift). Without the check, a street whose blocks look alike put the camera 120 m back
  // along it (docs/RESULTS.md, "Session 35").
  double odometry_gate_base = 1.0;
  double odometry_gate_per_path = 0.1;
  // BundleAdjusterOptions::weight_scale of the monocular initialisation's BA (a full BA of the
  // two keyframes), as local BA has it.
  double map_ba_weight_scale = 1.0;
  optimize::MapBaWeighting map_ba_weighting;  // of that BA too
};

// Where each tracked frame sits: relative to its reference keyframe, so that the final trajectory
// follows every later correction of the keyframes (ORB-SLAM's mlRelativeFramePoses).
struct FrameRecord {
  double timestamp = 0.0;
  map::KeyFrame* reference = nullptr;  // nullptr: the frame has no pose
  SE3 T_cr;
};

// Per-frame durations of the tracking stages, in ms (one sample per tracked frame).
struct TrackerTimings {
  std::vector<double> frame_to_frame_ms;  // motion model or reference keyframe, pose optimisation
  std::vector<double> local_map_ms;       // local map update, projection search, pose optimisation
  std::vector<double> keyframe_ms;        // keyframe decision and creation
  std::vector<double>
      map_lock_wait_ms;  // waiting for local mapping to release the map (every frame)
  // Each relocalisation attempt of a lost frame, successful or not: place recognition and every
  // candidate keyframe tried.
  std::vector<double> relocalization_ms;
};

// Place recognition for a lost frame: keyframes of map `map_id` that look like the frame, best
// first (loop closing's keyframe database; the tracker holds the map lock while it asks).
using PlaceRecognition =
    std::function<std::vector<map::KeyFrame*>(const Frame& frame, std::size_t map_id)>;

class Tracker {
 public:
  Tracker(map::Map& map, const map::CameraRig& rig, KeyframeSink& mapper, TrackerOptions options,
          std::uint64_t seed);

  // Tracks one frame; call with the map lock NOT held (the tracker takes it).
  TrackingState track(Frame frame);

  // Without it, relocalisation tries only the tracked map's most recent keyframes.
  void set_place_recognition(PlaceRecognition place_recognition) {
    place_recognition_ = std::move(place_recognition);
  }

  // A loaded map (map_file.h): the first frame, `first_frame_id`, relocalises in the map of
  // `reference`, a keyframe of it; if it cannot, the tracker goes on as after a loss (unless
  // localization_only, a new map: at once with stereo, after max_lost_frames when monocular).
  // Call before the first frame.
  void start_in_loaded_map(map::KeyFrame* reference, std::size_t first_frame_id);

  TrackingState state() const { return state_; }
  const Frame& last_frame() const { return last_frame_; }
  const std::vector<FrameRecord>& records() const { return records_; }
  const TrackerTimings& timings() const { return timings_; }
  int maps_started() const { return maps_started_; }
  int relocalizations() const { return relocalizations_; }
  // Localization-only: frames placed by visual odometry outside the map, and relocalisations
  // refused for being too far from it (TrackerOptions::odometry_gate_base).
  int odometry_frames() const { return odometry_frames_; }
  int refused_relocalizations() const { return relocalizer_.refused(); }
  // Frames on which the motion model was weakly supported and the reference keyframe was matched
  // by descriptor as well (see weak_motion_model_ratio).
  int weak_motion_model_frames() const { return weak_motion_model_frames_; }
  // The last frame wanted a keyframe that local mapping was too busy to take (monocular:
  // ORB-SLAM's rule refuses it; stereo: more than 2 were queued).
  bool keyframe_deferred() const { return keyframe_deferred_; }
  // Offline playback, once local mapping is idle again: gives it the keyframe the last frame
  // wanted while it was busy, if the last frame still qualifies. Takes the map lock. Returns
  // whether a keyframe was made.
  bool insert_deferred_keyframe();
  // Monocular depth for Algorithm 1 (saliency/depth_correction.h): the map points matched in the
  // last frame where the constant-velocity model puts them in the next frame (at the last pose
  // without a model), as distorted pixels and depths in map units. Empty unless tracking is OK.
  // A snapshot made at the end of track(), under its lock: asking for the lock afterwards made the
  // next frame wait for a whole local BA of monocular mapping, which does not yield the lock.
  const std::vector<saliency::DepthSample>& predicted_point_depths() const {
    return predicted_depths_;
  }
  // Why a monocular map has not been initialised yet (empty once it has).
  const std::string& initialization_status() const { return initialization_status_; }

 private:
  void initialize_stereo(Frame& frame);
  void initialize_monocular(Frame& frame);
  bool create_monocular_map(Frame& first, Frame& second, const std::vector<match::Match>& matches,
                            const TwoViewResult& result);
  // Motion model, or reference keyframe when the model is unavailable or weakly supported.
  bool track_frame_to_frame(Frame& frame);
  // Both return the inlier map-point matches after pose optimisation (outliers still flagged).
  int track_reference_keyframe(Frame& frame);
  static constexpr int kMinTemporalPoints = 100;  // ORB-SLAM's UpdateLastFrame
  // The second count adds the temporal points (stereo) to the map points.
  struct MotionModelInliers {
    int map_points = 0;
    int all = 0;
  };
  // The last frame's closest stereo points without a map point become temporal points, at least
  // `min_temporal_points` of the stereo points taken (with those beyond th_depth).
  MotionModelInliers track_with_motion_model(Frame& frame,
                                             int min_temporal_points = kMinTemporalPoints);
  bool track_local_map(Frame& frame);
  // Times the attempt, counts a success. With a prior, only poses within it count, and only the
  // place-recognition candidates nearest it are tried.
  bool relocalize(Frame& frame, const std::optional<PosePrior>& prior = std::nullopt);
  bool relocalize_in_tracked_map(Frame& frame, const std::optional<PosePrior>& prior);
  // Localization-only, stereo: relocalisation in the map near visual odometry's pose, or
  // odometry's pose (`by_odometry`) when it fails (TrackerOptions::odometry_gate_base).
  bool track_beyond_map(Frame& frame, bool& by_odometry);
  // Visual odometry: the motion model on the last frame's stereo points; where it fails (a turn
  // begins) those points matched by descriptor alone; after a few frames without a pose, the
  // last posed frame's (odometry_anchor_) matched so. Returns the inliers.
  MotionModelInliers odometry_pose(Frame& frame);
  // The map and temporal points of `from` matched to `frame` by descriptor, and the pose
  // optimised from `from`'s; returns the inliers.
  int match_points_by_descriptor(Frame& frame, const Frame& from) const;
  // A point of the last frame's stereo measurements, alive for one frame (add_temporal_points).
  static bool is_temporal_point(const map::MapPoint* mp);
  static void drop_temporal_points(Frame& frame);
  // Localization-only, stereo (else none): around the odometry pose of this frame if given, else
  // around the last pose unless it is more than max_lost_frames old.
  std::optional<PosePrior> localization_prior(std::size_t frame_id, const SE3* odometry_T_cw) const;
  void update_local_map(const Frame& frame);
  enum class KeyframeNeed { kNone, kInsert, kMappingBusy };
  KeyframeNeed need_new_keyframe(const Frame& frame) const;
  void create_keyframe(Frame& frame);
  void replace_bad_points(Frame& frame) const;
  void add_temporal_points(Frame& last, int min_points);
  void start_new_map(Frame& frame);
  void record(const Frame& frame);
  void predict_point_depths();   // fills predicted_depths_ from last_frame_; map lock held
  void follow_map_correction();  // map lock held
  void follow_map_rescaling(const SE3& T_cr, const map::KeyFrame& reference);

  map::Map& map_;
  const map::CameraRig& rig_;
  KeyframeSink& mapper_;
  TrackerOptions options_;
  Relocalizer relocalizer_;
  PlaceRecognition place_recognition_;

  TrackingState state_ = TrackingState::kNotInitialized;
  Frame last_frame_;
  std::optional<SE3> velocity_;    // T_cw(now) * T_wc(last)
  double last_frame_depth_ = 0.0;  // monocular: last_frame_'s median point depth when tracked
  map::KeyFrame* reference_keyframe_ = nullptr;
  map::KeyFrame* last_keyframe_ = nullptr;
  std::size_t last_keyframe_frame_id_ = 0;
  std::size_t last_relocalization_frame_id_ = 0;
  int inlier_matches_ = 0;
  std::vector<map::KeyFrame*> local_keyframes_;
  std::vector<map::KeyFrame*> voting_keyframes_;  // scratch of update_local_map
  std::size_t vote_rounds_ = 0;
  std::vector<map::MapPoint*> local_points_;
  // Short-lived stereo points of the last frame that help the motion model between keyframes.
  std::vector<std::unique_ptr<map::MapPoint>> temporal_points_;
  std::vector<FrameRecord> records_;
  std::vector<saliency::DepthSample> predicted_depths_;
  TrackerTimings timings_;
  std::optional<SE3> last_known_T_cw_;
  int maps_started_ = 0;
  int relocalizations_ = 0;
  bool odometry_ = false;     // the last frame was placed by visual odometry
  double odometry_path_ = 0;  // the path driven on odometry since the map was last tracked
  double last_step_ = 0;      // the camera centre's move into the last posed frame
  std::size_t last_pose_frame_id_ = 0;
  int odometry_frames_ = 0;
  std::size_t first_run_keyframe_id_ = 0;  // keyframes below it were loaded from a map file
  std::optional<Frame> odometry_anchor_;   // localization-only: the last posed frame before a loss
  std::size_t seen_big_change_ = 0;
  int weak_motion_model_frames_ = 0;
  bool keyframe_deferred_ = false;
  std::uint64_t seed_;
  std::unique_ptr<TwoViewInitializer> two_view_;
  std::optional<Frame> initial_frame_;  // monocular: first frame of the current two-view attempt
  // Its keypoints moved to where each was last matched: the centres of the next window search.
  std::vector<feature::OrbKeypoint> initial_search_keypoints_;
  std::string initialization_status_ = "not initialised: no frame yet";
  std::size_t lost_since_frame_id_ = 0;
};

}  // namespace sbaslam::tracking
