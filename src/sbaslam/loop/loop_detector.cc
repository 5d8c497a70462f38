#include "sbaslam/loop/loop_detector.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <set>
#include <unordered_set>

#include "sbaslam/loop/bow_matcher.h"
#include "sbaslam/loop/sim3_solver.h"
#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/optimize/sim3_refinement.h"

namespace sbaslam::loop {
namespace {

constexpr float kLoopSearchRadius = 10.0f;  // ORB-SLAM's th in ComputeSim3's projection search
// The least baseline between the two views, as a share of the median depth of the matched points,
// at which reprojection errors fix a similarity's scale.
constexpr double kMinScaleBaseline = 0.1;

using GroupsHolding = std::unordered_map<const map::KeyFrame*, std::vector<std::size_t>>;

// The groups holding any of `members`, ascending. seen_by[g] == stamp marks a group already
// listed, so the scratch vector serves every candidate of one query without clearing.
std::vector<std::size_t> groups_sharing_a_member(const GroupsHolding& groups_holding,
                                                 const std::vector<const map::KeyFrame*>& members,
                                                 std::size_t stamp,
                                                 std::vector<std::size_t>& seen_by) {
  std::vector<std::size_t> shared;
  for (const map::KeyFrame* member : members) {
    const auto it = groups_holding.find(member);
    if (it == groups_holding.end()) continue;
    for (const std::size_t g : it->second)
      if (seen_by[g] != stamp) {
        seen_by[g] = stamp;
        shared.push_back(g);
      }
  }
  std::sort(shared.begin(), shared.end());
  return shared;
}

std::vector<map::MapPoint*> neighbourhood_points(map::KeyFrame* loop) {
  std::vector<map::KeyFrame*> keyframes = loop->covisibles();
  keyframes.insert(keyframes.begin(), loop);
  std::unordered_set<const map::MapPoint*> seen;
  std::vector<map::MapPoint*> points;
  for (const map::KeyFrame* kf : keyframes) {
    for (map::MapPoint* mp : kf->map_points())
      if (mp && !mp->is_bad() && seen.insert(mp).second) points.push_back(mp);
  }
  return points;
}

std::vector<optimize::Sim3Correspondence> correspondences(const map::KeyFrame& kf1,
                                                          const map::KeyFrame& kf2,
                                                          const std::vector<KeypointPair>& pairs) {
  const feature::ScaleLevels& levels = kf1.rig().levels;
  std::vector<optimize::Sim3Correspondence> c;
  c.reserve(pairs.size());
  for (const KeypointPair& p : pairs) {
    const feature::OrbKeypoint& k1 = kf1.measurements().keypoints_un[p.keypoint1];
    const feature::OrbKeypoint& k2 = kf2.measurements().keypoints_un[p.keypoint2];
    optimize::Sim3Correspondence s;
    s.p1_c = kf1.T_cw() * kf1.map_point(p.keypoint1)->position();
    s.p2_c = kf2.T_cw() * kf2.map_point(p.keypoint2)->position();
    s.uv1 = Vec2(k1.x, k1.y);
    s.uv2 = Vec2(k2.x, k2.y);
    s.sigma2_1 = levels.sigma2[static_cast<std::size_t>(k1.octave)];
    s.sigma2_2 = levels.sigma2[static_cast<std::size_t>(k2.octave)];
    c.push_back(s);
  }
  return c;
}

// Reprojection errors fix a similarity's scale only through the baseline between the two views.
// Where the views nearly coincide (a revisit along the same path), scaling the points about the
// camera leaves every projection where it was: the refinement then wandered off RANSAC's 3D-3D
// scale (by a factor of 37 on a synthetic revisit of the same pose), so it keeps that scale.
bool scale_observable(const std::vector<optimize::Sim3Correspondence>& c, const Sim3& S12) {
  std::vector<double> depths;
  depths.reserve(c.size());
  for (const optimize::Sim3Correspondence& x : c) depths.push_back(x.p1_c.norm());
  if (depths.empty()) return false;
  const auto middle = depths.begin() + static_cast<long>(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return S12.translation().norm() >= kMinScaleBaseline * *middle;
}

}  // namespace

LoopDetector::LoopDetector(const map::CameraRig& rig, LoopDetectorOptions options)
    : rig_(rig), options_(options) {}

std::optional<DetectedLoop> LoopDetector::process(map::KeyFrame* kf, BowVector bow,
                                                  FeatureVector features,
                                                  const std::function<void()>& pause) {
  std::optional<DetectedLoop> loop;
  features_[kf] = std::move(features);
  if (kf->id() >= last_loop_keyframe_id_ + options_.min_keyframes_between_loops) {
    for (map::KeyFrame* candidate : consistent_candidates(kf, bow)) {
      if (pause) pause();
      if (kf->is_bad()) break;
      loop = verify(kf, candidate);
      if (loop) break;
    }
  }
  database_.add(kf, std::move(bow));
  return loop;
}

std::vector<map::KeyFrame*> LoopDetector::loop_candidates(const map::KeyFrame* kf,
                                                          const BowVector& bow) const {
  // The least similarity among the keyframes that share the view: a loop must look at least as
  // much alike as the keyframe's own neighbours do.
  std::set<const map::KeyFrame*> connected{kf};
  std::vector<const map::KeyFrame*> scored;
  for (const map::KeyFrame* covisible : kf->covisibles()) {
    connected.insert(covisible);
    if (!covisible->is_bad() && database_.bow_of(covisible)) scored.push_back(covisible);
  }
  double min_score = 1.0;
  for (const double score : database_.scores(bow, scored)) min_score = std::min(min_score, score);
  return database_.detect_loop_candidates(kf, bow, connected, min_score);
}

std::vector<map::KeyFrame*> LoopDetector::consistent_candidates(map::KeyFrame* kf,
                                                                const BowVector& bow) {
  const std::vector<map::KeyFrame*> candidates = loop_candidates(kf, bow);
  // Which of the previous keyframe's groups hold each keyframe: a candidate's group then finds the
  // groups it shares a keyframe with by lookups, not by intersecting it with each of them.
  GroupsHolding groups_holding;
  for (std::size_t g = 0; g < groups_.size(); ++g)
    for (const map::KeyFrame* member : groups_[g].keyframes) groups_holding[member].push_back(g);
  std::vector<ConsistentGroup> groups;
  std::vector<map::KeyFrame*> consistent;
  std::vector<char> group_extended(groups_.size(), 0);
  std::vector<std::size_t> seen_by(groups_.size(), candidates.size());  // candidate index
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    map::KeyFrame* candidate = candidates[c];
    ConsistentGroup group;
    group.keyframes.push_back(candidate);
    for (const map::KeyFrame* covisible : candidate->covisibles())
      group.keyframes.push_back(covisible);
    const std::vector<std::size_t> shared =
        groups_sharing_a_member(groups_holding, group.keyframes, c, seen_by);
    bool enough = false;
    for (const std::size_t g : shared) {
      const int consistency = groups_[g].consistency + 1;
      if (!group_extended[g]) {
        groups.push_back({group.keyframes, consistency});
        group_extended[g] = 1;
      }
      if (consistency >= options_.consistency && !enough) {
        consistent.push_back(candidate);
        enough = true;
      }
    }
    if (shared.empty()) groups.push_back({std::move(group.keyframes), 0});
  }
  groups_ = std::move(groups);
  return consistent;
}

std::optional<DetectedLoop> LoopDetector::verify(map::KeyFrame* kf, map::KeyFrame* candidate) {
  const auto candidate_features = features_.find(candidate);
  if (candidate->is_bad() || candidate_features == features_.end()) return std::nullopt;
  const std::vector<KeypointPair> pairs =
      match_keyframes_by_bow(*kf, features_[kf], *candidate, candidate_features->second);
  if (static_cast<int>(pairs.size()) < options_.min_bow_matches) return std::nullopt;
  const std::vector<optimize::Sim3Correspondence> c = correspondences(*kf, *candidate, pairs);
  Sim3RansacOptions ransac;
  ransac.fix_scale = rig_.stereo;
  ransac.min_inliers = options_.min_sim3_inliers;
  ransac.seed = options_.seed + ransac_runs_++;
  const Sim3RansacResult hypothesis = ransac_sim3(c, rig_.camera, rig_.camera, ransac);
  if (!hypothesis.found) return std::nullopt;
  optimize::Sim3RefinementOptions refinement;
  refinement.fix_scale = rig_.stereo || !scale_observable(c, hypothesis.S12);
  const optimize::Sim3RefinementResult refined =
      optimize::refine_sim3(c, hypothesis.S12, rig_.camera, rig_.camera, refinement);
  if (refined.inlier_count < options_.min_sim3_inliers ||
      refined.inlier_count < options_.min_inlier_ratio * static_cast<double>(pairs.size()))
    return std::nullopt;

  DetectedLoop loop;
  loop.current = kf;
  loop.loop = candidate;
  loop.bow_matches = static_cast<int>(pairs.size());
  loop.sim3_inliers = refined.inlier_count;
  loop.S_cw = refined.S12 * Sim3(candidate->T_cw());
  loop.matched.assign(kf->keypoint_count(), nullptr);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (refined.inliers[k])
      loop.matched[pairs[k].keypoint1] = candidate->map_point(pairs[k].keypoint2);
  loop.loop_points = neighbourhood_points(candidate);
  match_points_by_similarity(*kf, loop.S_cw, loop.loop_points, loop.matched, kLoopSearchRadius);
  loop.loop_matches = static_cast<int>(
      std::count_if(loop.matched.begin(), loop.matched.end(), [](auto* mp) { return mp; }));
  spdlog::debug("loop candidate {} for keyframe {}: {} BoW matches, {} Sim3 inliers, {} matches",
                candidate->id(), kf->id(), loop.bow_matches, loop.sim3_inliers, loop.loop_matches);
  if (loop.loop_matches < options_.min_loop_matches) return std::nullopt;
  return loop;
}

int match_points_by_similarity(const map::KeyFrame& kf, const Sim3& S_cw,
                               const std::vector<map::MapPoint*>& points,
                               std::vector<map::MapPoint*>& matched, float radius) {
  const map::CameraRig& rig = kf.rig();
  const map::Measurements& m = kf.measurements();
  const Vec3 center_w = S_cw.inverse() * Vec3::Zero();
  std::unordered_set<const map::MapPoint*> already;
  std::vector<char> taken(matched.size(), 0);
  for (std::size_t i = 0; i < matched.size(); ++i) {
    taken[i] = matched[i] != nullptr;
    if (matched[i]) already.insert(matched[i]);
  }
  std::vector<match::ProjectedPoint> projected;
  std::vector<map::MapPoint*> sources;
  for (map::MapPoint* mp : points) {
    if (mp->is_bad() || already.count(mp) || mp->descriptor().empty()) continue;
    const Vec3 p_c = S_cw * mp->position();
    if (p_c.z() <= 0.0) continue;
    const Vec2 uv = rig.camera.project(p_c);
    if (!rig.in_image(uv)) continue;
    const Vec3 po = mp->position() - center_w;
    const double distance = po.norm();
    if (distance < mp->min_distance() || distance > mp->max_distance()) continue;
    if (po.dot(mp->normal()) < 0.5 * distance) continue;
    match::ProjectedPoint p;
    p.u = static_cast<float>(uv.x());
    p.v = static_cast<float>(uv.y());
    p.level = mp->predict_level(distance, rig.levels);
    p.descriptor = mp->descriptor().ptr<std::uint8_t>();
    projected.push_back(p);
    sources.push_back(mp);
  }
  match::ProjectionOptions options;
  options.radius = radius;
  options.nn_ratio = 1.0f;
  options.max_distance = match::kThresholdLow;
  const match::FrameView view{m.keypoints_un, m.descriptors, m.grid, rig.levels};
  int added = 0;
  for (const match::Match& match : match::match_by_projection(projected, view, options, &taken)) {
    matched[static_cast<std::size_t>(match.train)] = sources[static_cast<std::size_t>(match.query)];
    ++added;
  }
  return added;
}

}  // namespace sbaslam::loop
