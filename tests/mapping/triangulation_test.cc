// New map points between two monocular keyframes (create_new_map_points): which pairs the
// parallax gate lets through, on exact projections of points at known depths.

#include "sbaslam/mapping/triangulation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "helper/camera_rig.h"
#include "sbaslam/match/feature_grid.h"

namespace sbaslam::mapping {
namespace {

constexpr double kBaseline = 0.5;  // metres, sideways between the two keyframes
constexpr double kAnchorDepth = 10.0;

double degrees(double radians) {
  return radians * 180.0 / M_PI;
}

// Two keyframes kBaseline apart that share 20 mapped anchor points (so that they are covisible and
// have a median depth), plus one unmatched keypoint pair per candidate point.
class TriangulationTest : public ::testing::Test {
 protected:
  // 20 candidates on a grid of first-keyframe pixels (shifted right by `shift`), `depth` metres
  // deep.
  void add_candidates(double depth, double shift) {
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 5; ++col)
        candidates_.push_back(point_at(Vec2(100.0 + shift + 90.0 * col, 60.0 + 80.0 * row), depth));
  }

  Vec3 point_at(const Vec2& pixel, double depth) const {
    return depth * Vec3(rig_.camera.normalized(pixel).homogeneous());
  }

  // Builds both keyframes; candidates come after the anchors in each.
  void build() {
    std::vector<Vec3> points;
    for (int i = 0; i < 20; ++i)
      points.push_back(point_at(Vec2(100.0 + 22.0 * i, 420.0), kAnchorDepth));
    points.insert(points.end(), candidates_.begin(), candidates_.end());
    cv::Mat descriptors(static_cast<int>(points.size()), 32, CV_8U);
    cv::RNG rng(7);
    rng.fill(descriptors, cv::RNG::UNIFORM, 0, 256);
    first_ = add_keyframe(SE3(), points, descriptors);
    first_->set_origin();
    second_ = add_keyframe(SE3(SO3(), Vec3(-kBaseline, 0.0, 0.0)), points, descriptors);
    for (std::size_t i = 0; i < 20; ++i) {
      map::MapPoint* mp = map_.create_map_point(points[i], first_);
      for (map::KeyFrame* kf : {first_, second_}) {
        mp->add_observation(kf, i);
        kf->add_map_point(mp, i);
      }
    }
    first_->update_connections();
    second_->update_connections();
  }

  map::KeyFrame* add_keyframe(const SE3& T_cw, const std::vector<Vec3>& points,
                              const cv::Mat& descriptors) {
    auto m = std::make_shared<map::Measurements>();
    for (const Vec3& p : points) {
      const Vec2 pixel = rig_.camera.project(T_cw * p);
      feature::OrbKeypoint kp;
      kp.x = static_cast<float>(pixel.x());
      kp.y = static_cast<float>(pixel.y());
      m->keypoints.push_back(kp);
    }
    m->keypoints_un = m->keypoints;
    m->descriptors = descriptors.clone();
    m->u_right.assign(points.size(), -1.0f);
    m->depth.assign(points.size(), -1.0f);
    m->weights.assign(points.size(), 1.0f);
    m->grid = match::FeatureGrid(m->keypoints_un, rig_.bounds);
    const std::size_t id = frame_id_++;
    return map_.create_keyframe(id, 0.1 * static_cast<double>(id), T_cw, std::move(m), &rig_);
  }

  // The angle between the two keyframes' rays to a point, in degrees.
  double parallax_deg(const Vec3& p) const {
    const Vec3 ray1 = p - first_->camera_center(), ray2 = p - second_->camera_center();
    return degrees(std::acos(ray1.dot(ray2) / (ray1.norm() * ray2.norm())));
  }

  map::CameraRig rig_ = test::vga_mono_rig();
  map::Map map_;
  std::size_t frame_id_ = 0;
  std::vector<Vec3> candidates_;
  map::KeyFrame* first_ = nullptr;
  map::KeyFrame* second_ = nullptr;
};

TEST_F(TriangulationTest, ParallaxGateDecidesWhichPointsAreCreated) {
  add_candidates(kBaseline / std::tan(1.8 * M_PI / 180.0), 0.0);   // between 1.15 and 2.5
  add_candidates(kBaseline / std::tan(4.0 * M_PI / 180.0), 45.0);  // above both
  build();
  int narrow = 0, wide = 0;
  for (const Vec3& p : candidates_) {
    const double parallax = parallax_deg(p);
    ASSERT_TRUE((parallax > 1.2 && parallax < 2.4) || parallax > 2.6) << parallax;
    (parallax < 2.5 ? narrow : wide) += 1;
  }
  ASSERT_EQ(narrow, 20);
  ASSERT_EQ(wide, 20);

  const double gate = std::cos(2.5 * M_PI / 180.0);
  const std::vector<map::MapPoint*> strict = create_new_map_points(map_, first_, 20, gate);
  EXPECT_EQ(strict.size(), 20u);
  for (const map::MapPoint* mp : strict) {
    EXPECT_GT(parallax_deg(mp->position()), 2.5);
    EXPECT_NEAR(mp->position().z(), kBaseline / std::tan(4.0 * M_PI / 180.0), 0.05);
  }
}

TEST_F(TriangulationTest, OrbSlamGateAlsoTakesTheNarrowPairs) {
  add_candidates(kBaseline / std::tan(1.8 * M_PI / 180.0), 0.0);
  build();
  const std::vector<map::MapPoint*> created = create_new_map_points(map_, first_, 20);
  EXPECT_EQ(created.size(), 20u);
  for (const map::MapPoint* mp : created) EXPECT_LT(parallax_deg(mp->position()), 2.5);
}

}  // namespace
}  // namespace sbaslam::mapping
