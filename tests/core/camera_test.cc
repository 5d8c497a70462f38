#include "sbaslam/core/camera.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

namespace sbaslam {
namespace {

// EuRoC cam0: strong barrel distortion, a demanding case for the inverse.
PinholeCamera euroc_cam0() {
  return PinholeCamera({458.654, 457.296, 367.215, 248.375},
                       {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0});
}
// TUM fr1: all five coefficients, with k3.
PinholeCamera tum1() {
  return PinholeCamera({517.306408, 516.469215, 318.643040, 255.313989},
                       {0.262383, -0.953104, -0.005358, 0.002628, 1.163314});
}

TEST(CameraTest, ProjectUnprojectRoundTrip) {
  const PinholeCamera cam = euroc_cam0();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-2.0, 2.0), z(0.5, 20.0);
  for (int i = 0; i < 100; ++i) {
    const Vec3 p(xy(rng), xy(rng), z(rng));
    const Vec3 bearing = cam.unproject(cam.project(p));
    EXPECT_NEAR(bearing.norm(), 1.0, 1e-12);
    EXPECT_LT((bearing - p.normalized()).norm(), 1e-12);
  }
}

TEST(CameraTest, ProjectJacobianMatchesFiniteDifferences) {
  const PinholeCamera cam = tum1();
  const Vec3 p(0.3, -0.2, 2.5);
  const Eigen::Matrix<double, 2, 3> J = cam.project_jacobian(p);
  for (int k = 0; k < 3; ++k) {
    Vec3 dp = Vec3::Zero();
    dp[k] = 1e-6;
    const Vec2 numeric = (cam.project(p + dp) - cam.project(p - dp)) / 2e-6;
    EXPECT_LT((J.col(k) - numeric).norm(), 1e-5) << k;
  }
}

TEST(CameraTest, DistortMatchesOpenCvProjectPoints) {
  for (const PinholeCamera& cam : {euroc_cam0(), tum1()}) {
    std::vector<cv::Point3d> points;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> xy(-0.6, 0.6);
    for (int i = 0; i < 200; ++i) points.emplace_back(xy(rng), xy(rng), 1.0);
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(cam.K()),
                      cam.dist_coeffs(), expected);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 p(points[i].x, points[i].y, points[i].z);
      const Vec2 uv = cam.project_distorted(p);
      EXPECT_NEAR(uv.x(), expected[i].x, 1e-9);
      EXPECT_NEAR(uv.y(), expected[i].y, 1e-9);
    }
  }
}

TEST(CameraTest, UndistortMatchesConvergedOpenCvUndistortPoints) {
  for (const auto& [cam, width, height] :
       {std::make_tuple(euroc_cam0(), 752, 480), std::make_tuple(tum1(), 640, 480)}) {
    std::vector<cv::Point2d> raw;
    for (int v = 0; v <= height; v += 24)
      for (int u = 0; u <= width; u += 24) raw.emplace_back(u, v);
    std::vector<cv::Point2d> expected;
    // OpenCV's default stops after 5 iterations; converge it fully for a fair reference.
    cv::undistortPoints(raw, expected, cv::Mat(cam.K()), cam.dist_coeffs(), cv::noArray(),
                        cv::Mat(cam.K()), cv::TermCriteria(cv::TermCriteria::COUNT, 1000, 0.0));
    double worst = 0.0;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const Vec2 uv = cam.undistort(Vec2(raw[i].x, raw[i].y));
      worst = std::max(worst, (uv - Vec2(expected[i].x, expected[i].y)).norm());
      // And it inverts distort().
      EXPECT_LT((cam.distort(uv) - Vec2(raw[i].x, raw[i].y)).norm(), 1e-9);
    }
    EXPECT_LT(worst, 1e-6);
  }
}

TEST(CameraTest, UndistortPointVectorAndNoDistortion) {
  const PinholeCamera cam = euroc_cam0();
  std::vector<cv::Point2f> points = {{10.f, 10.f}, {367.f, 248.f}, {740.f, 470.f}};
  const std::vector<cv::Point2f> raw = points;
  cam.undistort(points);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec2 expected = cam.undistort(Vec2(raw[i].x, raw[i].y));
    EXPECT_NEAR(points[i].x, expected.x(), 1e-3);
    EXPECT_NEAR(points[i].y, expected.y(), 1e-3);
  }
  // Barrel distortion pushes the corner outwards once undistorted.
  EXPECT_LT(points[0].x, raw[0].x);

  const PinholeCamera ideal(PinholeIntrinsics{500, 500, 320, 240});
  EXPECT_FALSE(ideal.has_distortion());
  EXPECT_EQ(ideal.undistort(Vec2(1.5, 2.5)), Vec2(1.5, 2.5));
  EXPECT_EQ(ideal.distort(Vec2(1.5, 2.5)), Vec2(1.5, 2.5));
}

// TUM-VI's cam0 (512x512, 195-degree lens): Kannala-Brandt, as ORB-SLAM3's TUM-VI settings give it.
PinholeCamera tum_vi_cam0() {
  return PinholeCamera(
      {190.97847715128717, 190.9733070521226, 254.93170605935475, 256.8974428996504},
      KannalaBrandtDistortion{0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                              0.00020293673591811182});
}

TEST(CameraTest, FisheyeDistortMatchesOpenCvFisheye) {
  const PinholeCamera cam = tum_vi_cam0();
  EXPECT_TRUE(cam.is_fisheye());
  EXPECT_TRUE(cam.has_distortion());
  std::vector<cv::Point3d> points;
  std::mt19937 rng(5);
  // Rays up to 80 degrees off the axis (tan 80 = 5.7).
  std::uniform_real_distribution<double> xy(-4.0, 4.0);
  for (int i = 0; i < 300; ++i) points.emplace_back(xy(rng), xy(rng), 1.0);
  std::vector<cv::Point2d> expected;
  cv::fisheye::projectPoints(points, expected, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                             cv::Mat(cam.K()), cam.dist_coeffs());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec2 uv = cam.project_distorted(Vec3(points[i].x, points[i].y, points[i].z));
    EXPECT_NEAR(uv.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(uv.y(), expected[i].y, 1e-9);
  }
}

TEST(CameraTest, FisheyeUndistortInvertsDistortInsideTheField) {
  const PinholeCamera cam = tum_vi_cam0();
  for (int v = 0; v <= 512; v += 16)
    for (int u = 0; u <= 512; u += 16) {
      const Vec2 raw(u, v);
      const double theta = cam.field_angle(raw);
      // The lens sees beyond 90 degrees; the pinhole plane does not.
      if (theta >= 85.0 * M_PI / 180.0) {
        EXPECT_FALSE(cam.sees_on_pinhole_plane(raw));
        continue;
      }
      const Vec2 uv = cam.undistort(raw);
      EXPECT_LT((cam.distort(uv) - raw).norm(), 1e-9) << raw.transpose();
      EXPECT_NEAR(std::atan(cam.normalized(uv).norm()), theta, 1e-12);
      EXPECT_EQ(cam.sees_on_pinhole_plane(raw), theta <= kMaxFisheyeFieldAngle);
    }
  // The image's corners lie beyond 90 degrees: a 195-degree lens.
  EXPECT_GT(cam.field_angle(Vec2(0.0, 0.0)), M_PI / 2.0);
}

TEST(CameraTest, FisheyeUndistortWithinFieldStopsAtTheFieldLimit) {
  const PinholeCamera cam = tum_vi_cam0();
  const Vec2 centre(cam.intrinsics().cx, cam.intrinsics().cy);
  // Inside the limit it is undistort(); beyond, the ray at the limit in the same direction.
  const Vec2 inside = centre + Vec2(60.0, -40.0);
  EXPECT_EQ(cam.undistort_within_field(inside), cam.undistort(inside));
  const Vec2 corner(0.0, 0.0);
  const Vec2 clamped = cam.undistort_within_field(corner);
  EXPECT_NEAR(std::atan(cam.normalized(clamped).norm()), kMaxFisheyeFieldAngle, 1e-12);
  const Vec2 direction = (corner - centre).normalized();
  EXPECT_LT(((clamped - centre).normalized() - direction).norm(), 1e-3);
  // A pinhole camera is unaffected.
  const PinholeCamera plain = euroc_cam0();
  EXPECT_EQ(plain.undistort_within_field(corner), plain.undistort(corner));
  EXPECT_TRUE(plain.sees_on_pinhole_plane(corner));
}

TEST(CameraTest, FisheyeFromSettings) {
  CameraSettings settings;
  settings.intrinsics = {300.0, 300.0, 320.0, 240.0};
  settings.model = CameraModel::kKannalaBrandt8;
  settings.fisheye = {0.01, 0.0, 0.0, 0.0};
  const PinholeCamera cam(settings);
  EXPECT_TRUE(cam.is_fisheye());
  EXPECT_EQ(cam.dist_coeffs().cols, 4);
  // Equidistant at zero coefficients: a ray at 45 degrees lands at radius f * pi / 4, not f.
  const PinholeCamera equidistant(settings.intrinsics, KannalaBrandtDistortion{});
  const Vec2 uv = equidistant.project_distorted(Vec3(1.0, 0.0, 1.0));
  EXPECT_NEAR(uv.x() - 320.0, 300.0 * M_PI / 4.0, 1e-9);
  settings.model = CameraModel::kPinhole;
  EXPECT_FALSE(PinholeCamera(settings).is_fisheye());
}

TEST(CameraTest, StereoRigDisparityAndTriangulation) {
  const StereoRig rig({718.856, 718.856, 607.1928, 185.2157}, 386.1448 / 718.856);
  EXPECT_NEAR(rig.bf, 386.1448, 1e-9);
  const Vec3 p(1.2, -0.4, 8.0);
  const PinholeCamera left(rig.intrinsics);
  const Vec2 uv = left.project(p);
  const double u_right = rig.right_u(uv.x(), p.z());
  // The right camera sits at +baseline along x.
  const Vec2 uv_right = left.project(p - Vec3(rig.baseline, 0.0, 0.0));
  EXPECT_NEAR(u_right, uv_right.x(), 1e-9);
  EXPECT_NEAR(rig.depth_from_disparity(uv.x() - u_right), 8.0, 1e-9);
  EXPECT_NEAR(rig.disparity_from_depth(8.0), uv.x() - u_right, 1e-9);
  EXPECT_LT((rig.triangulate(uv, u_right) - p).norm(), 1e-9);
}

}  // namespace
}  // namespace sbaslam
