// The map's bookkeeping on hand-built keyframes: observations, covisibility weights, the spanning
// tree when a keyframe is removed, and point replacement.

#include "sbaslam/map/map.h"

#include <gtest/gtest.h>

#include "helper/camera_rig.h"
#include "sbaslam/match/feature_grid.h"

namespace sbaslam::map {
namespace {

class MapTest : public ::testing::Test {
 protected:
  // A keyframe with `n` monocular keypoints spread over the image.
  KeyFrame* add_keyframe(int n, double x) {
    auto m = std::make_shared<Measurements>();
    for (int i = 0; i < n; ++i) {
      feature::OrbKeypoint kp;
      kp.x = static_cast<float>(10 + (i * 37) % 600);
      kp.y = static_cast<float>(10 + (i * 53) % 460);
      m->keypoints.push_back(kp);
    }
    m->keypoints_un = m->keypoints;
    m->descriptors = cv::Mat::zeros(n, 32, CV_8U);
    for (int i = 0; i < n; ++i) m->descriptors.at<std::uint8_t>(i, i % 32) = 0xFF;
    m->u_right.assign(static_cast<std::size_t>(n), -1.0f);
    m->depth.assign(static_cast<std::size_t>(n), -1.0f);
    m->weights.assign(static_cast<std::size_t>(n), 1.0f);
    m->grid = match::FeatureGrid(m->keypoints_un, rig_.bounds);
    const std::size_t id = frame_id_++;
    KeyFrame* kf = map_.create_keyframe(id, 0.1 * static_cast<double>(id),
                                        SE3(SO3(), Vec3(-x, 0, 0)), std::move(m), &rig_);
    if (map_.keyframe_count() == 1) kf->set_origin();
    return kf;
  }

  // A point seen by keypoint `index` of each keyframe given.
  MapPoint* add_point(const std::vector<KeyFrame*>& kfs, std::size_t index) {
    MapPoint* mp = map_.create_map_point(Vec3(0.1 * index, 0.0, 10.0), kfs.front());
    for (KeyFrame* kf : kfs) {
      mp->add_observation(kf, index);
      kf->add_map_point(mp, index);
    }
    return mp;
  }

  CameraRig rig_ = test::vga_mono_rig();
  Map map_;
  std::size_t frame_id_ = 0;
};

TEST_F(MapTest, CovisibilityWeightsCountSharedPointsWithThreshold) {
  KeyFrame* a = add_keyframe(60, 0.0);
  KeyFrame* b = add_keyframe(60, 1.0);
  KeyFrame* c = add_keyframe(60, 2.0);
  for (std::size_t i = 0; i < 20; ++i) add_point({a, b, c}, i);  // 20 shared by all
  for (std::size_t i = 20; i < 30; ++i) add_point({b, c}, i);    // 10 more for b-c
  c->update_connections();
  EXPECT_EQ(c->connection_weight(b), 30);
  EXPECT_EQ(c->connection_weight(a), 20);
  EXPECT_EQ(b->connection_weight(c), 30);  // connections are reciprocal
  ASSERT_EQ(c->best_covisibles(1).size(), 1u);
  EXPECT_EQ(c->best_covisibles(1)[0], b);
  EXPECT_EQ(c->covisibles_with_weight_at_least(25).size(), 1u);
  EXPECT_EQ(c->parent(), b);  // attached to the tree under its strongest neighbour
}

TEST_F(MapTest, RemovingAKeyframeReparentsItsChildrenAndUnlinksItsPoints) {
  // Keyframes join one after the other, as in a run: b sees a's points, then c sees both.
  KeyFrame* a = add_keyframe(80, 0.0);
  KeyFrame* b = add_keyframe(80, 1.0);
  std::vector<MapPoint*> shared;
  for (std::size_t i = 0; i < 20; ++i) shared.push_back(add_point({a, b}, i));
  b->update_connections();
  KeyFrame* c = add_keyframe(80, 2.0);
  for (MapPoint* mp : shared) {
    mp->add_observation(c,
                        mp->keypoint_in(a) >= 0 ? static_cast<std::size_t>(mp->keypoint_in(a)) : 0);
    c->add_map_point(mp, static_cast<std::size_t>(mp->keypoint_in(c)));
  }
  for (std::size_t i = 20; i < 40; ++i) add_point({b, c}, i);
  c->update_connections();
  ASSERT_EQ(b->parent(), a);
  ASSERT_EQ(c->parent(), b);

  b->set_bad();
  EXPECT_TRUE(b->is_bad());
  EXPECT_EQ(map_.keyframe_count(), 2u);
  EXPECT_EQ(c->parent(), a);  // re-parented to the keyframe still in the tree
  EXPECT_EQ(c->connection_weight(b), 0);
  for (MapPoint* mp : shared) EXPECT_FALSE(mp->is_in_keyframe(b));
  // T_cp places the removed keyframe relative to its parent for trajectory assembly.
  EXPECT_TRUE((b->T_cp() * a->T_cw()).matrix().isApprox(b->T_cw().matrix(), 1e-12));
}

TEST_F(MapTest, OriginKeyframeIsNeverRemoved) {
  KeyFrame* a = add_keyframe(10, 0.0);
  a->set_bad();
  EXPECT_FALSE(a->is_bad());
  EXPECT_EQ(map_.keyframe_count(), 1u);
}

// ORB-SLAM3's KeyFramesInMap: tracking asks how young the map it tracks is, not the whole atlas.
TEST_F(MapTest, KeyframesAreCountedPerMapAndMoveWithAMerge) {
  KeyFrame* a = add_keyframe(40, 0.0);
  KeyFrame* b = add_keyframe(40, 1.0);
  add_point({a, b}, 0);
  const std::size_t younger = map_.new_map_id();
  EXPECT_NE(younger, a->map_id());
  KeyFrame* c = map_.create_keyframe(7, 0.7, SE3(), a->measurements_ptr(), &rig_, younger);
  KeyFrame* d = map_.create_keyframe(8, 0.8, SE3(), a->measurements_ptr(), &rig_, younger);
  KeyFrame* e = map_.create_keyframe(9, 0.9, SE3(), a->measurements_ptr(), &rig_, younger);
  EXPECT_EQ(map_.keyframe_count_in_map(a->map_id()), 2u);
  EXPECT_EQ(map_.keyframe_count_in_map(younger), 3u);
  EXPECT_EQ(map_.keyframe_count_in_map(younger + 1), 0u);
  EXPECT_GT(map_.new_map_id(), younger);

  d->set_bad();
  d->set_bad();  // a second call must not count the keyframe out twice
  EXPECT_EQ(map_.keyframe_count_in_map(younger), 2u);
  map_.move_keyframes_to_map(younger, a->map_id());
  EXPECT_EQ(c->map_id(), a->map_id());
  EXPECT_EQ(e->map_id(), a->map_id());
  EXPECT_EQ(map_.keyframe_count_in_map(a->map_id()), 4u);
  EXPECT_EQ(map_.keyframe_count_in_map(younger), 0u);
  EXPECT_EQ(map_.keyframe_count(), 4u);
}

TEST_F(MapTest, PointWithTooFewObservationsTurnsBad) {
  KeyFrame* a = add_keyframe(10, 0.0);
  KeyFrame* b = add_keyframe(10, 1.0);
  KeyFrame* c = add_keyframe(10, 2.0);
  MapPoint* mp = add_point({a, b, c}, 3);
  EXPECT_EQ(mp->observation_count(), 3);
  mp->erase_observation(c);
  EXPECT_TRUE(mp->is_bad());  // two monocular observations are not enough to keep it
  EXPECT_EQ(a->map_point(3), nullptr);
  EXPECT_EQ(map_.map_point_count(), 0u);
}

TEST_F(MapTest, ReplaceMovesObservationsToTheSurvivor) {
  KeyFrame* a = add_keyframe(10, 0.0);
  KeyFrame* b = add_keyframe(10, 1.0);
  KeyFrame* c = add_keyframe(10, 2.0);
  MapPoint* keep = add_point({a, b}, 1);
  MapPoint* duplicate = add_point({c}, 2);
  duplicate->replace_with(keep);
  EXPECT_TRUE(duplicate->is_bad());
  EXPECT_EQ(duplicate->replaced_by(), keep);
  EXPECT_EQ(c->map_point(2), keep);
  EXPECT_TRUE(keep->is_in_keyframe(c));
  EXPECT_EQ(keep->observation_count(), 3);
}

TEST_F(MapTest, DescriptorIsTheMedoidOfTheObservations) {
  KeyFrame* a = add_keyframe(10, 0.0);
  KeyFrame* b = add_keyframe(10, 1.0);
  KeyFrame* c = add_keyframe(10, 2.0);
  MapPoint* mp = map_.create_map_point(Vec3(0, 0, 10), a);
  // Keypoints 0, 0 and 1 have descriptors with 0xFF in byte 0, byte 0 and byte 1.
  mp->add_observation(a, 0);
  mp->add_observation(b, 0);
  mp->add_observation(c, 1);
  mp->update_descriptor();
  ASSERT_FALSE(mp->descriptor().empty());
  EXPECT_EQ(mp->descriptor().at<std::uint8_t>(0, 0), 0xFF);
  EXPECT_EQ(mp->descriptor().at<std::uint8_t>(0, 1), 0x00);
}

}  // namespace
}  // namespace sbaslam::map
