#include "sbaslam/core/map_worlds.h"

#include <gtest/gtest.h>

namespace sbaslam {
namespace {

PoseInMap pose_at(double stamp, double x, std::size_t map_id) {
  return {stamp, SE3(SO3(), Vec3(x, 0.0, 0.0)), map_id};
}

// Frames 0-2 in map 0, 3-4 in map 1 (its own scale), 5 back in map 0.
std::vector<PoseInMap> two_maps() {
  return {pose_at(0.0, 0.0, 0), pose_at(0.1, 1.0, 0), pose_at(0.2, 2.0, 0),
          pose_at(0.3, 0.5, 1), pose_at(0.4, 0.6, 1), pose_at(0.5, 3.0, 0)};
}

TEST(SplitByWorld, MonocularMapsOutsideTheBiggestGoToTheirOwnWorlds) {
  const TrajectoriesByWorld worlds = split_by_world(two_maps(), {{0, 2}, {1, 7}}, false);
  EXPECT_EQ(worlds.main_map_id, 1u);
  ASSERT_EQ(worlds.main.size(), 2u);
  EXPECT_DOUBLE_EQ(worlds.main.stamps[0], 0.3);
  EXPECT_DOUBLE_EQ(worlds.main.poses[1].translation().x(), 0.6);
  ASSERT_EQ(worlds.own_worlds.size(), 1u);
  const Trajectory& older = worlds.own_worlds.at(0);
  ASSERT_EQ(older.size(), 4u);
  EXPECT_DOUBLE_EQ(older.stamps[3], 0.5);  // the input's order is kept
  EXPECT_DOUBLE_EQ(older.poses[3].translation().x(), 3.0);
}

TEST(SplitByWorld, ATieKeepsTheOlderMap) {
  const TrajectoriesByWorld worlds = split_by_world(two_maps(), {{0, 4}, {1, 4}}, false);
  EXPECT_EQ(worlds.main_map_id, 0u);
  EXPECT_EQ(worlds.main.size(), 4u);
  EXPECT_EQ(worlds.own_worlds.at(1).size(), 2u);
}

TEST(SplitByWorld, AMapWithNoLiveKeyframesLeftIsNeverMain) {
  // Map 1 was merged into map 2: its count entry is gone, its keyframes now say map 2.
  const std::vector<PoseInMap> poses = {pose_at(0.0, 0.0, 0), pose_at(0.1, 1.0, 2)};
  const TrajectoriesByWorld worlds = split_by_world(poses, {{0, 0}, {2, 3}}, false);
  EXPECT_EQ(worlds.main_map_id, 2u);
  EXPECT_EQ(worlds.own_worlds.at(0).size(), 1u);
}

TEST(SplitByWorld, MetricMapsShareTheFirstMapsWorld) {
  const TrajectoriesByWorld worlds = split_by_world(two_maps(), {{0, 2}, {1, 7}}, true);
  EXPECT_EQ(worlds.main.size(), 6u);
  EXPECT_TRUE(worlds.own_worlds.empty());
  EXPECT_DOUBLE_EQ(worlds.main.stamps[3], 0.3);
}

}  // namespace
}  // namespace sbaslam
