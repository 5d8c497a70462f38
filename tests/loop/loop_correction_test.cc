#include "sbaslam/loop/loop_correction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <mutex>

#include "helper/circular_map.h"
#include "helper/synthetic_views.h"
#include "sbaslam/loop/global_bundle_adjustment.h"

namespace sbaslam::loop {
namespace {

constexpr std::size_t kCurrent = 39;  // at 390 degrees: the place of keyframe 3
constexpr std::size_t kLoop = 3;

// The loop as detection would report it: the current keyframe's true pose in the loop
// keyframe's world, and its duplicated points matched to the first lap's.
DetectedLoop seam_loop(const test::CircularMap& c) {
  DetectedLoop loop;
  loop.current = c.keyframes[kCurrent];
  loop.loop = c.keyframes[kLoop];
  loop.S_cw = Sim3(c.ideal_T_cw(kCurrent, kLoop));
  loop.matched.assign(loop.current->keypoint_count(), nullptr);
  for (std::size_t k = 0; k < loop.matched.size(); ++k) {
    map::MapPoint* first = c.first_point[c.world_point_of[kCurrent][k]];
    if (first != loop.current->map_point(k)) loop.matched[k] = first;
  }
  std::vector<map::KeyFrame*> neighbourhood = loop.loop->covisibles();
  neighbourhood.push_back(loop.loop);
  for (map::KeyFrame* kf : neighbourhood)
    for (map::MapPoint* mp : kf->map_points())
      if (mp &&
          std::find(loop.loop_points.begin(), loop.loop_points.end(), mp) == loop.loop_points.end())
        loop.loop_points.push_back(mp);
  return loop;
}

struct PoseErrors {
  double max_deg = 0.0, max_m = 0.0;
};

// How far the keyframes are from where they belong in keyframe `anchor`'s world.
PoseErrors errors_in_world_of(const test::CircularMap& c, std::size_t anchor) {
  PoseErrors e;
  for (std::size_t i = 0; i < c.keyframes.size(); ++i) {
    const SE3 ideal = c.ideal_T_cw(i, anchor);
    const SE3& estimate = c.keyframes[i]->T_cw();
    e.max_deg = std::max(e.max_deg, test::rotation_error_deg(ideal, estimate));
    e.max_m = std::max(e.max_m,
                       (ideal.inverse().translation() - estimate.inverse().translation()).norm());
  }
  return e;
}

double position_error(const test::CircularMap& c, std::size_t i, std::size_t anchor) {
  return (c.ideal_T_cw(i, anchor).inverse().translation() - c.keyframes[i]->camera_center()).norm();
}

TEST(LoopCorrection, ClosesTheSeamAndSpreadsTheDriftOverTheLap) {
  auto c = test::make_circular_map();
  const PoseErrors before = errors_in_world_of(*c, kLoop);
  const double seam_before = position_error(*c, kCurrent, kLoop);
  const std::size_t big_change = c->map.big_change_index();
  const LoopCorrectionReport report = correct_loop(c->map, seam_loop(*c), false);
  const PoseErrors after = errors_in_world_of(*c, kLoop);
  EXPECT_GT(before.max_deg, 1.5);
  EXPECT_GT(seam_before, 0.5);
  EXPECT_LT(position_error(*c, kCurrent, kLoop), 0.05 * seam_before);
  // The essential graph trusts every edge alike, so some of the drift stays (global BA's part).
  EXPECT_LT(after.max_deg, 0.2 * before.max_deg);
  EXPECT_LT(after.max_m, 0.4 * before.max_m);
  EXPECT_EQ(report.graph_keyframes, c->keyframes.size());
  EXPECT_GT(report.graph_edges, c->keyframes.size());
  EXPECT_LT(report.graph_final_cost, 0.01 * report.graph_initial_cost);
  EXPECT_EQ(c->map.big_change_index(), big_change + 2);  // the neighbourhood's move, the graph's
  EXPECT_EQ(c->keyframes[kCurrent]->loop_edges().count(c->keyframes[kLoop]), 1u);
}

TEST(LoopCorrection, FusesTheSecondLapsDuplicatesIntoTheFirstLapsPoints) {
  auto c = test::make_circular_map();
  map::KeyFrame* current = c->keyframes[kCurrent];
  const auto first_lap_points = [&] {
    int n = 0;
    for (std::size_t k = 0; k < current->keypoint_count(); ++k)
      if (current->map_point(k) == c->first_point[c->world_point_of[kCurrent][k]]) ++n;
    return n;
  };
  const int shared_before = first_lap_points();
  const LoopCorrectionReport report = correct_loop(c->map, seam_loop(*c), false);
  EXPECT_GT(report.fused_points, 0u);
  EXPECT_GT(first_lap_points(), shared_before + 50);
  // The fusion links the two laps in the covisibility graph.
  EXPECT_GT(current->connection_weight(c->keyframes[kLoop]), 50);
}

TEST(LoopCorrection, RigidCorrectionClosesTheSeamToo) {
  auto c = test::make_circular_map();
  const double seam_before = position_error(*c, kCurrent, kLoop);
  correct_loop(c->map, seam_loop(*c), true);
  EXPECT_LT(position_error(*c, kCurrent, kLoop), 0.05 * seam_before);
  EXPECT_LT(errors_in_world_of(*c, kLoop).max_deg, 0.5);
  for (map::MapPoint* mp : c->map.map_points()) ASSERT_TRUE(mp->position().allFinite());
}

TEST(LoopCorrection, GlobalBundleAdjustmentThenRemovesTheRestOfTheDrift) {
  auto c = test::make_circular_map();
  correct_loop(c->map, seam_loop(*c), false);
  const PoseErrors corrected = errors_in_world_of(*c, 0);
  std::mutex mutex;
  std::unique_lock<std::mutex> lock(mutex);
  optimize::BundleAdjusterOptions options;
  options.iterations = 10;
  options.refine_iterations = 0;
  const std::size_t big_change = c->map.big_change_index();
  const GlobalBundleAdjustmentReport report =
      run_global_bundle_adjustment(c->map, c->rig, options, lock);
  EXPECT_TRUE(lock.owns_lock());
  EXPECT_EQ(report.keyframes, c->keyframes.size());
  EXPECT_EQ(c->map.big_change_index(), big_change + 1);
  // The origin keyframe anchors global BA, so the map settles in its world.
  const PoseErrors adjusted = errors_in_world_of(*c, 0);
  EXPECT_LT(adjusted.max_deg, 0.25 * corrected.max_deg);
  EXPECT_LT(adjusted.max_m, 0.25 * corrected.max_m);
}

// A keyframe tracking made after the loop's keyframe, still queued for local mapping (no place in
// the spanning tree), keeps its pose relative to the current keyframe.
TEST(LoopCorrection, KeyframesAwaitingMappingMoveWithTheCurrentOne) {
  auto c = test::make_circular_map();
  map::KeyFrame* current = c->keyframes[kCurrent];
  const SE3 offset(SO3::exp(Vec3(0.0, -0.17, 0.0)), Vec3(0.0, 0.0, -3.0));
  map::KeyFrame* queued = c->map.create_keyframe(100, 100.0, offset * current->T_cw(),
                                                 current->measurements_ptr(), &c->rig);
  const SE3 moved_before = queued->T_cw();
  correct_loop(c->map, seam_loop(*c), false);
  const SE3 relative = queued->T_cw() * current->T_cw().inverse();
  EXPECT_LT((relative.translation() - offset.translation()).norm(), 0.01);
  EXPECT_LT(test::rotation_error_deg(relative, offset), 0.01);
  EXPECT_GT((queued->T_cw().inverse().translation() - moved_before.inverse().translation()).norm(),
            0.3);
}

TEST(LoopCorrection, KeyframesOfAnotherMapAreNotTheSameMap) {
  auto c = test::make_circular_map();
  map::KeyFrame* other =
      c->map.create_keyframe(1000, 100.0, SE3(), c->keyframes[0]->measurements_ptr(), &c->rig);
  other->set_origin();
  EXPECT_TRUE(same_map(c->map, *c->keyframes[0], *c->keyframes[kCurrent]));
  EXPECT_FALSE(same_map(c->map, *c->keyframes[kCurrent], *other));
}

// The drive as two maps: tracking was lost before keyframe 20 and started a new map there, its
// world off the first map's by a jump (and, for a monocular map, a scale of its own).
constexpr std::size_t kNewMapFrom = 20;

std::unique_ptr<test::CircularMap> two_maps(double new_map_scale = 1.0) {
  test::CircularMapOptions o;
  o.new_map_from = static_cast<int>(kNewMapFrom);
  auto c = test::make_circular_map(o);
  if (new_map_scale != 1.0) {
    for (std::size_t i = kNewMapFrom; i < c->keyframes.size(); ++i) {
      map::KeyFrame* kf = c->keyframes[i];
      kf->set_pose(SE3(kf->T_cw().so3(), new_map_scale * kf->T_cw().translation()));
      for (map::MapPoint* mp : kf->map_points())
        if (mp && mp->reference_keyframe() == kf) mp->set_position(new_map_scale * mp->position());
    }
  }
  return c;
}

// The loop as detection measures it when the current map has its own scale: the camera's
// coordinates are new_map_scale times the metric ones.
DetectedLoop scaled_seam_loop(const test::CircularMap& c, double new_map_scale) {
  DetectedLoop loop = seam_loop(c);
  loop.S_cw = Sim3(new_map_scale, SO3(), Vec3::Zero()) * loop.S_cw;
  return loop;
}

TEST(MapMerge, BringsTheNewerMapIntoTheLoopsWorldWithItsKeyframesRigidly) {
  auto c = two_maps();
  ASSERT_FALSE(same_map(c->map, *c->keyframes[kLoop], *c->keyframes[kCurrent]));
  ASSERT_NE(c->keyframes[kLoop]->map_id(), c->keyframes[kCurrent]->map_id());
  const double seam_before = position_error(*c, kCurrent, kLoop);
  std::vector<SE3> relative_before, old_before;
  for (std::size_t i = 0; i < c->keyframes.size(); ++i) {
    relative_before.push_back(c->keyframes[i]->T_cw() * c->keyframes[kCurrent]->T_wc());
    old_before.push_back(c->keyframes[i]->T_cw());
  }
  const std::size_t big_change = c->map.big_change_index();
  const MapMergeReport report = merge_maps(c->map, seam_loop(*c));
  EXPECT_GT(seam_before, 3.0);  // the jump
  EXPECT_LT(position_error(*c, kCurrent, kLoop), 1e-9);
  EXPECT_EQ(report.moved_keyframes, c->keyframes.size() - kNewMapFrom);
  for (std::size_t i = 0; i < c->keyframes.size(); ++i) {
    const SE3& T = c->keyframes[i]->T_cw();
    if (i < kNewMapFrom) {  // the older map stays where it is
      EXPECT_EQ(T.matrix(), old_before[i].matrix()) << "keyframe " << i;
    } else {
      const SE3 relative = T * c->keyframes[kCurrent]->T_wc();
      EXPECT_LT((relative.translation() - relative_before[i].translation()).norm(), 1e-9);
      EXPECT_LT(test::rotation_error_deg(relative, relative_before[i]), 1e-7);
    }
  }
  EXPECT_TRUE(same_map(c->map, *c->keyframes[kLoop], *c->keyframes[kNewMapFrom]));
  // Tracking counts the merged map's keyframes as one map's (how young a map is).
  EXPECT_EQ(c->map.keyframe_count_in_map(c->keyframes[kLoop]->map_id()), c->keyframes.size());
  EXPECT_EQ(c->keyframes[kNewMapFrom]->map_id(), c->keyframes[kLoop]->map_id());
  EXPECT_TRUE(c->keyframes[0]->is_origin());
  EXPECT_FALSE(c->keyframes[kNewMapFrom]->is_origin());
  EXPECT_EQ(c->keyframes[kCurrent]->parent(), c->keyframes[kLoop]);
  EXPECT_GT(report.fused_points, 0u);
  EXPECT_GT(c->keyframes[kCurrent]->connection_weight(c->keyframes[kLoop]), 50);
  EXPECT_EQ(c->map.big_change_index(), big_change + 1);
}

TEST(MapMerge, TakesAMonocularMapsOwnScaleOut) {
  constexpr double kScale = 2.5;
  auto c = two_maps(kScale);
  const double step_before =
      (c->keyframes[kCurrent]->camera_center() - c->keyframes[kCurrent - 1]->camera_center())
          .norm();
  merge_maps(c->map, scaled_seam_loop(*c, kScale));
  EXPECT_LT(position_error(*c, kCurrent, kLoop), 1e-9);
  const double step_after =
      (c->keyframes[kCurrent]->camera_center() - c->keyframes[kCurrent - 1]->camera_center())
          .norm();
  EXPECT_NEAR(step_after, step_before / kScale, 1e-9);
  // A point of the newer map lands where the older map's world has it, up to the newer map's
  // own drift since keyframe 20 (under 20 steps of 0.02 m and 0.05 degrees).
  map::KeyFrame* current = c->keyframes[kCurrent];
  for (std::size_t k = 0; k < current->keypoint_count(); k += 50) {
    const map::MapPoint* mp = current->map_point(k);
    if (!mp || mp->is_bad()) continue;
    const Vec3 ideal = c->drift[kLoop] * c->world_points[c->world_point_of[kCurrent][k]];
    EXPECT_LT((mp->position() - ideal).norm(), 0.5) << "keypoint " << k;
  }
}

// Relocalised into the first map, tracking may find the loop from there to the younger map: the
// younger map still moves, so the first map's world stays the trajectory's.
TEST(MapMerge, MovesTheYoungerMapWhicheverSideFoundTheLoop) {
  auto c = two_maps();
  std::vector<SE3> old_before;
  for (std::size_t i = 0; i < kNewMapFrom; ++i) old_before.push_back(c->keyframes[i]->T_cw());
  DetectedLoop loop;
  loop.current = c->keyframes[kLoop];
  loop.loop = c->keyframes[kCurrent];
  loop.S_cw = Sim3(c->true_T_cw[kLoop] * c->drift[kCurrent].inverse());
  loop.matched.assign(loop.current->keypoint_count(), nullptr);
  const MapMergeReport report = merge_maps(c->map, loop);
  EXPECT_EQ(report.moved_keyframes, c->keyframes.size() - kNewMapFrom);
  for (std::size_t i = 0; i < kNewMapFrom; ++i)
    EXPECT_EQ(c->keyframes[i]->T_cw().matrix(), old_before[i].matrix()) << "keyframe " << i;
  EXPECT_LT(position_error(*c, kCurrent, kLoop), 1e-9);
  EXPECT_TRUE(c->keyframes[0]->is_origin());
  EXPECT_FALSE(c->keyframes[kNewMapFrom]->is_origin());
  EXPECT_EQ(c->keyframes[kCurrent]->parent(), c->keyframes[kLoop]);
  EXPECT_TRUE(same_map(c->map, *c->keyframes[0], *c->keyframes[kNewMapFrom]));
  EXPECT_EQ(c->keyframes[kCurrent]->map_id(), c->keyframes[0]->map_id());
}

// The spanning tree stays a tree through the merge: every keyframe reaches the first map's origin
// without a cycle, and each is among its parent's children.
TEST(MapMerge, JoinsTheSpanningTreesIntoOne) {
  auto c = two_maps();
  merge_maps(c->map, seam_loop(*c));
  for (map::KeyFrame* kf : c->keyframes) {
    std::size_t steps = 0;
    const map::KeyFrame* node = kf;
    for (; node->parent() && steps <= c->keyframes.size(); ++steps) {
      EXPECT_EQ(node->parent()->children().count(const_cast<map::KeyFrame*>(node)), 1u);
      node = node->parent();
    }
    EXPECT_EQ(node, c->keyframes[0]) << "keyframe " << kf->id();
  }
}

// What tracking and local mapping do while the essential graph is solved without the map lock.
struct WindowOutcome {
  SE3 nudged;              // a keyframe local mapping moved in the window
  SE3 made_relative;       // a keyframe tracking made in the window, relative to the current one
  Vec3 made_point_c;       // its new point, in its camera
  Vec3 made_point_c_then;  // the same, when made
};

const SE3 kMadeOffset(SO3::exp(Vec3(0.0, -0.17, 0.0)), Vec3(0.0, 0.0, -3.0));
const SE3 kNudge(SO3::exp(Vec3(0.002, 0.0, 0.001)), Vec3(0.01, -0.02, 0.0));

WindowOutcome correct_with_changes_in_the_window(bool nudge) {
  auto c = test::make_circular_map();
  map::KeyFrame* current = c->keyframes[kCurrent];
  map::KeyFrame* nudged = c->keyframes[kCurrent - 2];
  map::KeyFrame* made = nullptr;
  map::MapPoint* point = nullptr;
  WindowOutcome out;
  correct_loop(c->map, seam_loop(*c), true, [&](const std::function<void()>& solve) {
    solve();
    made = c->map.create_keyframe(100, 100.0, kMadeOffset * current->T_cw(),
                                  current->measurements_ptr(), &c->rig);
    point = c->map.create_map_point(made->T_wc() * Vec3(0.5, -0.2, 8.0), made);
    out.made_point_c_then = made->T_cw() * point->position();
    if (nudge) nudged->set_pose(kNudge * nudged->T_cw());
  });
  out.nudged = nudged->T_cw();
  out.made_relative = made->T_cw() * current->T_cw().inverse();
  out.made_point_c = made->T_cw() * point->position();
  return out;
}

TEST(LoopCorrection, WhatChangesWhileTheGraphIsSolvedFollowsTheCorrection) {
  const WindowOutcome plain = correct_with_changes_in_the_window(false);
  const WindowOutcome nudged = correct_with_changes_in_the_window(true);
  EXPECT_LT((plain.made_relative.translation() - kMadeOffset.translation()).norm(), 1e-9);
  EXPECT_LT(test::rotation_error_deg(plain.made_relative, kMadeOffset), 1e-7);
  EXPECT_LT((plain.made_point_c - plain.made_point_c_then).norm(), 1e-9);
  // Local mapping's move survives the correction.
  const SE3 expected = kNudge * plain.nudged;
  EXPECT_LT((nudged.nudged.translation() - expected.translation()).norm(), 1e-9);
  EXPECT_LT(test::rotation_error_deg(nudged.nudged, expected), 1e-7);
}

}  // namespace
}  // namespace sbaslam::loop
