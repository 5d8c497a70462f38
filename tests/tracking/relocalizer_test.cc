#include "sbaslam/tracking/relocalizer.h"

#include <gtest/gtest.h>

#include "helper/synthetic_views.h"

namespace sbaslam::tracking {
namespace {

map::CameraRig kitti_rig() {
  map::CameraRig rig;
  const optimize::RectifiedCamera c = test::kitti_like_camera();
  rig.camera = PinholeCamera(PinholeIntrinsics{c.fx, c.fy, c.cx, c.cy});
  rig.levels = feature::ScaleLevels::make(8, 1.2);
  rig.bounds = cv::Rect2f(0, 0, 1241, 376);
  return rig;
}

struct PnpProblem {
  SE3 truth;
  std::vector<Vec3> points;
  std::vector<Vec2> pixels;
  std::vector<int> levels;
  std::vector<bool> outlier;
};

PnpProblem make_problem(double outlier_fraction, std::mt19937& rng) {
  PnpProblem p;
  p.truth = SE3(SO3::exp(Vec3(0.03, -0.2, 0.01)), Vec3(1.0, 0.2, -3.0));
  const optimize::RectifiedCamera cam = test::kitti_like_camera();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (const Vec3& x_c : test::random_points(300, rng)) {
    const Vec3 x_w = p.truth.inverse() * x_c;  // points in front of the true camera
    const optimize::PixelObservation obs = test::project(cam, p.truth, x_w, false);
    Vec2 uv(obs.u + noise(rng), obs.v + noise(rng));
    const bool bad = unit(rng) < outlier_fraction;
    if (bad) uv = Vec2(1241.0 * unit(rng), 376.0 * unit(rng));
    p.points.push_back(x_w);
    p.pixels.push_back(uv);
    p.levels.push_back(0);
    p.outlier.push_back(bad);
  }
  return p;
}

TEST(PnpRansac, RecoversThePoseDespiteFortyPercentOutliers) {
  std::mt19937 rng(5);
  const PnpProblem p = make_problem(0.4, rng);
  std::mt19937_64 ransac_rng(11);
  const PnpResult r =
      solve_pnp_ransac(p.points, p.pixels, p.levels, kitti_rig(), PnpRansacOptions{}, ransac_rng);
  ASSERT_TRUE(r.success);
  EXPECT_LT((r.T_cw.translation() - p.truth.translation()).norm(), 0.05);
  EXPECT_LT(test::rotation_error_deg(r.T_cw, p.truth), 0.2);
  int wrong = 0;
  for (std::size_t i = 0; i < p.outlier.size(); ++i) wrong += p.outlier[i] && r.inlier[i];
  EXPECT_LE(wrong, 2);  // a random pixel can land near the true projection by chance
}

TEST(PnpRansac, SameSeedSameAnswer) {
  std::mt19937 rng(6);
  const PnpProblem p = make_problem(0.3, rng);
  std::mt19937_64 a(3), b(3);
  const PnpResult ra = solve_pnp_ransac(p.points, p.pixels, p.levels, kitti_rig(), {}, a);
  const PnpResult rb = solve_pnp_ransac(p.points, p.pixels, p.levels, kitti_rig(), {}, b);
  ASSERT_TRUE(ra.success);
  EXPECT_EQ(ra.T_cw.matrix(), rb.T_cw.matrix());
  EXPECT_EQ(ra.inlier, rb.inlier);
}

TEST(PnpRansac, RefusesPureNoise) {
  std::mt19937 rng(7);
  const PnpProblem p = make_problem(1.0, rng);
  std::mt19937_64 ransac_rng(1);
  PnpRansacOptions options;
  options.min_inliers = 30;
  EXPECT_FALSE(
      solve_pnp_ransac(p.points, p.pixels, p.levels, kitti_rig(), options, ransac_rng).success);
}

}  // namespace
}  // namespace sbaslam::tracking
