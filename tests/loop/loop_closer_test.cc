#include "sbaslam/loop/loop_closer.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "helper/circular_map.h"
#include "helper/synthetic_views.h"

namespace sbaslam::loop {
namespace {

LoopCloserOptions closer_options() {
  LoopCloserOptions options;
  options.global_bundle_adjustment.iterations = 10;
  options.global_bundle_adjustment.refine_iterations = 0;
  return options;
}

double max_rotation_error_deg(const test::CircularMap& c) {
  double worst = 0.0;
  for (std::size_t i = 0; i < c.keyframes.size(); ++i)
    worst = std::max(worst, test::rotation_error_deg(c.ideal_T_cw(i, 0), c.keyframes[i]->T_cw()));
  return worst;
}

// The drive with a second map from keyframe 20 on, as tracking makes one after a loss.
std::unique_ptr<test::CircularMap> two_maps(const std::optional<SE3>& jump = std::nullopt) {
  test::CircularMapOptions o;
  o.new_map_from = 20;
  if (jump) o.map_jump = *jump;
  return test::make_circular_map(o);
}

LoopCloserReport run_lock_step(test::CircularMap& c, const LoopCloserOptions& options) {
  const Vocabulary vocabulary = test::vocabulary_of(c);
  LoopCloser closer(c.map, c.rig, vocabulary, options);
  for (map::KeyFrame* kf : c.keyframes) closer.insert_keyframe(kf);
  closer.process_queue();
  return closer.report();
}

TEST(LoopCloser, ClosesTheSecondLapsLoopAndAdjustsTheWholeMap) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  const double drift_before = max_rotation_error_deg(*c);
  LoopCloser closer(c->map, c->rig, vocabulary, closer_options());
  for (map::KeyFrame* kf : c->keyframes) closer.insert_keyframe(kf);
  closer.process_queue();
  const LoopCloserReport report = closer.report();
  EXPECT_EQ(report.keyframes_checked, c->keyframes.size());
  ASSERT_EQ(report.loops.size(), 1u);
  EXPECT_EQ(report.loops_rejected, 0u);
  const LoopClosure& loop = report.loops[0];
  EXPECT_GE(loop.keyframe_id, 30u);
  EXPECT_LE(loop.loop_keyframe_id, 8u);
  EXPECT_GT(loop.path_length, 90.0);  // 3.5 m between keyframes
  EXPECT_LT(loop.implied_correction, 0.05 * loop.path_length);
  EXPECT_EQ(loop.global_ba.keyframes, c->keyframes.size());
  EXPECT_LT(max_rotation_error_deg(*c), 0.25 * drift_before);
}

TEST(LoopCloser, RejectsALoopThatWouldMoveTheMapMoreThanDriftCan) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopCloserOptions options = closer_options();
  options.max_correction_ratio = 1e-4;  // 1 cm per 100 m: the lap drifted more than that
  LoopCloser closer(c->map, c->rig, vocabulary, options);
  const SE3 last_before = c->keyframes.back()->T_cw();
  for (map::KeyFrame* kf : c->keyframes) closer.insert_keyframe(kf);
  closer.process_queue();
  EXPECT_TRUE(closer.report().loops.empty());
  EXPECT_GE(closer.report().loops_rejected, 1u);
  EXPECT_EQ(c->keyframes.back()->T_cw().matrix(), last_before.matrix());
  EXPECT_EQ(c->map.big_change_index(), 0u);
}

// The second lap in a map of its own, as after a loss: the loop back to the first lap merges the
// two, where a loop within one map would be corrected.
TEST(LoopCloser, MergesANewerMapIntoTheOlderOneAtTheLoop) {
  auto c = two_maps();
  const LoopCloserReport report = run_lock_step(*c, closer_options());
  ASSERT_EQ(report.loops.size(), 1u);
  const LoopClosure& merge = report.loops[0];
  EXPECT_TRUE(merge.merge);
  EXPECT_GE(merge.keyframe_id, 30u);
  EXPECT_LE(merge.loop_keyframe_id, 8u);
  EXPECT_EQ(merge.merge_report.moved_keyframes, c->keyframes.size() - 20);
  EXPECT_GT(merge.translation, 3.0);  // the jump between the maps' worlds
  EXPECT_LE(merge.implied_correction, merge.allowed_correction);
  EXPECT_EQ(merge.global_ba.keyframes, c->keyframes.size());
  EXPECT_TRUE(same_map(c->map, *c->keyframes[0], *c->keyframes.back()));
  // Global BA after the merge leaves only drift: the newer map's keyframes near their place in
  // the first keyframe's world, as after a loop within one map.
  for (std::size_t i = 20; i < c->keyframes.size(); ++i)
    EXPECT_LT(test::rotation_error_deg(c->ideal_T_cw(i, 0), c->keyframes[i]->T_cw()), 1.0) << i;
}

// The younger map was anchored where tracking last knew its pose, so a merge may move it by the
// way the camera could have gone while lost (two keyframe steps at its last speed here) plus
// drift; one place that only looks like another implies more.
TEST(LoopCloser, RejectsAMergeThatWouldMoveTheYoungerMapFurtherThanTheLossExplains) {
  auto c = two_maps(SE3(SO3(), Vec3(40.0, 0.0, 0.0)));
  const LoopCloserReport report = run_lock_step(*c, closer_options());
  EXPECT_TRUE(report.loops.empty());
  EXPECT_GE(report.loops_rejected, 1u);
  EXPECT_FALSE(same_map(c->map, *c->keyframes[0], *c->keyframes.back()));
  EXPECT_EQ(c->map.big_change_index(), 0u);
}

TEST(LoopCloser, LeavesTheMapsApartWhenMergingIsOff) {
  auto c = two_maps();
  LoopCloserOptions options = closer_options();
  options.merge_maps = false;
  EXPECT_TRUE(run_lock_step(*c, options).loops.empty());
  EXPECT_FALSE(same_map(c->map, *c->keyframes[0], *c->keyframes.back()));
  EXPECT_EQ(c->map.big_change_index(), 0u);
}

TEST(LoopCloser, OnItsOwnThreadClosesTheSameLoop) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopCloser closer(c->map, c->rig, vocabulary, closer_options());
  closer.start();
  for (map::KeyFrame* kf : c->keyframes) closer.insert_keyframe(kf);
  closer.stop();  // finishes the queue first
  const LoopCloserReport report = closer.report();
  EXPECT_EQ(report.keyframes_checked, c->keyframes.size());
  ASSERT_EQ(report.loops.size(), 1u);
  EXPECT_LE(report.loops[0].loop_keyframe_id, 8u);
}

// Detection's time excludes its wait for the map lock: beside monocular mapping, which holds the
// lock for a whole keyframe, the wait was once reported as detection's own cost.
TEST(LoopCloser, ReportsTheWaitForTheMapLockApartFromDetection) {
  auto c = test::make_circular_map();
  const Vocabulary vocabulary = test::vocabulary_of(*c);
  LoopCloser closer(c->map, c->rig, vocabulary, closer_options());
  closer.insert_keyframe(c->keyframes[0]);
  constexpr auto kHeld = std::chrono::milliseconds(400);
  std::promise<void> holding;
  std::thread mapping([&] {
    std::lock_guard<std::mutex> lock(c->map.mutex());
    holding.set_value();
    std::this_thread::sleep_for(kHeld);
  });
  holding.get_future().wait();
  closer.process_queue();
  mapping.join();
  const LoopCloserReport report = closer.report();
  ASSERT_EQ(report.map_lock_wait_ms.size(), 1u);
  ASSERT_EQ(report.detection_ms.size(), 1u);
  // The lock was taken before detection began and held for 400 ms.
  EXPECT_GE(report.map_lock_wait_ms[0] + report.detection_ms[0], 390.0);
  EXPECT_GE(report.map_lock_wait_ms[0], 200.0);
  EXPECT_LT(report.detection_ms[0], 200.0);
}

TEST(LoopCloser, LoopThreadIsIdlePolicyOnlyWhileTrackingExtracts) {
  map::Map map;
  const map::CameraRig rig;
  const Vocabulary vocabulary;
  LoopCloser closer(map, rig, vocabulary, LoopCloserOptions{});
  EXPECT_EQ(closer.thread_policy(), -1);  // no thread yet
  closer.start();
  if (!closer.yields_cores()) GTEST_SKIP() << "this process may not leave SCHED_IDLE";
  EXPECT_EQ(closer.thread_policy(), SCHED_OTHER);
  closer.yield_cores(true);
  EXPECT_EQ(closer.thread_policy(), SCHED_IDLE);
  closer.yield_cores(false);
  EXPECT_EQ(closer.thread_policy(), SCHED_OTHER);
  closer.stop();
}

TEST(LoopCloser, SwitchedOffYieldingLeavesThePolicyAlone) {
  map::Map map;
  const map::CameraRig rig;
  const Vocabulary vocabulary;
  LoopCloserOptions options;
  options.yield_cores_to_extraction = false;
  LoopCloser closer(map, rig, vocabulary, options);
  closer.start();
  EXPECT_FALSE(closer.yields_cores());
  closer.yield_cores(true);
  EXPECT_EQ(closer.thread_policy(), SCHED_OTHER);
  closer.stop();
}

}  // namespace
}  // namespace sbaslam::loop
