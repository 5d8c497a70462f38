#pragma once
// Loop detection (ORB-SLAM2's LoopClosing::DetectLoop and ComputeSim3): a keyframe's bag of
// words finds earlier keyframes that look alike; a candidate counts once the candidates of three
// consecutive keyframes agree on a place; then its map points must fit the keyframe's under one
// similarity (SE3 with stereo depth), found by RANSAC, refined, and confirmed by projecting the
// loop's neighbourhood.

#include <cstdint>
#include <functional>
#include <optional>
#include <unordered_map>
#include <vector>

#include "sbaslam/loop/keyframe_database.h"
#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/map/map.h"

namespace sbaslam::loop {

struct LoopDetectorOptions {
  std::size_t min_keyframes_between_loops = 10;  // also the least keyframes before the first
  int consistency = 3;                           // consecutive keyframes agreeing on a place
  int min_bow_matches = 20;
  int min_sim3_inliers = 20;
  // Share of the BoW matches the refined similarity must explain. A place whose descriptor matches
  // mostly disagree with the geometry is ambiguous (repeated facades): on the synthetic city a loop
  // with 21 of 92 was 3 m off and made the map worse; true loops there explain 60-85 %.
  double min_inlier_ratio = 0.5;
  int min_loop_matches = 40;  // after the projection search
  std::uint64_t seed = 0;     // RANSAC
};

struct DetectedLoop {
  map::KeyFrame* current = nullptr;
  map::KeyFrame* loop = nullptr;
  // The current keyframe's world-to-camera similarity that agrees with the loop keyframe.
  Sim3 S_cw;
  std::vector<map::MapPoint*> matched;      // per keypoint of `current`: a loop point, or nullptr
  std::vector<map::MapPoint*> loop_points;  // of the loop keyframe and its covisibles
  int bow_matches = 0;
  int sim3_inliers = 0;
  int loop_matches = 0;
};

class LoopDetector {
 public:
  LoopDetector(const map::CameraRig& rig, LoopDetectorOptions options);

  // Looks for a loop closed by kf, then files kf for later queries. Map lock held; `pause`, if
  // set, is called before each candidate's verification and may let others take the lock for a
  // while (keyframes may turn bad meanwhile; those are skipped).
  std::optional<DetectedLoop> process(map::KeyFrame* kf, BowVector bow, FeatureVector features,
                                      const std::function<void()>& pause = {});
  // Files kf for later queries without looking for a loop (the keyframes of a loaded map).
  void file(map::KeyFrame* kf, BowVector bow, FeatureVector features) {
    features_[kf] = std::move(features);
    database_.add(kf, std::move(bow));
  }
  // After a correction: the next loop needs min_keyframes_between_loops new keyframes.
  void loop_closed_at(const map::KeyFrame& kf) { last_loop_keyframe_id_ = kf.id(); }
  std::size_t keyframes_filed() const { return database_.size(); }
  // The database's keyframes of map `map_id` that look like `bow`, best first (any thread; the
  // caller holds the map lock).
  std::vector<map::KeyFrame*> relocalization_candidates(const BowVector& bow,
                                                        std::size_t map_id) const {
    return database_.detect_relocalization_candidates(bow, map_id);
  }

 private:
  struct ConsistentGroup {
    std::vector<const map::KeyFrame*> keyframes;  // a candidate and its covisibles
    int consistency = 0;
  };

  // The database's candidates scoring at least as high as kf's least similar covisible.
  std::vector<map::KeyFrame*> loop_candidates(const map::KeyFrame* kf, const BowVector& bow) const;
  std::vector<map::KeyFrame*> consistent_candidates(map::KeyFrame* kf, const BowVector& bow);
  std::optional<DetectedLoop> verify(map::KeyFrame* kf, map::KeyFrame* candidate);

  const map::CameraRig& rig_;
  LoopDetectorOptions options_;
  KeyFrameDatabase database_;
  std::unordered_map<const map::KeyFrame*, FeatureVector> features_;
  std::vector<ConsistentGroup> groups_;
  std::size_t last_loop_keyframe_id_ = 0;
  std::uint64_t ransac_runs_ = 0;
};

// The points of `points` that project, under S_cw, onto unmatched keypoints of kf (ORB-SLAM's
// SearchByProjection with a similarity): fills `matched` (one slot per keypoint) and returns how
// many it added.
int match_points_by_similarity(const map::KeyFrame& kf, const Sim3& S_cw,
                               const std::vector<map::MapPoint*>& points,
                               std::vector<map::MapPoint*>& matched, float radius);

}  // namespace sbaslam::loop
