#include "sbaslam/core/stereo_rectifier.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "helper/fixture_copy.h"
#include "helper/orbslam2_stereo.h"
#include "sbaslam/core/error.h"
#include "sbaslam/io/euroc_sensor.h"

namespace sbaslam {
namespace {

struct EurocRig {
  io::EurocCameraSensor cam0, cam1;
  SE3 T_c1_c2;
};

EurocRig euroc_rig() {
  const std::string mav0 = test::euroc_fixture_dir() + "/mav0";
  EurocRig rig;
  rig.cam0 = io::read_euroc_camera_sensor(mav0 + "/cam0/sensor.yaml");
  rig.cam1 = io::read_euroc_camera_sensor(mav0 + "/cam1/sensor.yaml");
  rig.T_c1_c2 = rig.cam0.T_BS.inverse() * rig.cam1.T_BS;
  return rig;
}

TEST(StereoRectifierTest, EurocRigGeometry) {
  const EurocRig e = euroc_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const StereoRig& rig = rectifier.rig();
  // Rectification keeps the distance between the optical centres.
  EXPECT_NEAR(rig.baseline, e.T_c1_c2.translation().norm(), 1e-9);
  EXPECT_NEAR(rig.baseline, 0.110078, 1e-6);
  EXPECT_NEAR(rig.bf, rig.baseline * rig.intrinsics.fx, 1e-9);
  EXPECT_GT(rig.intrinsics.fx, 300.0);
  EXPECT_LT(rig.intrinsics.fx, 500.0);
  EXPECT_EQ(rectifier.image_size(), cv::Size(752, 480));
  // In the rectified frame the right camera's centre lies on +x.
  const Vec3 centre = rectifier.T_rect_cam0() * e.T_c1_c2.translation();
  EXPECT_NEAR(centre.x(), rig.baseline, 1e-9);
  EXPECT_NEAR(centre.y(), 0.0, 1e-9);
  EXPECT_NEAR(centre.z(), 0.0, 1e-9);
  // A small rotation (the rig is nearly fronto-parallel).
  EXPECT_GT(rectifier.R_cam0_rect().angle(), 1e-4);
  EXPECT_LT(rectifier.R_cam0_rect().angle(), 0.05);
  EXPECT_TRUE(
      (rectifier.T_cam0_rect() * rectifier.T_rect_cam0()).matrix().isApprox(Mat4::Identity()));
}

// A 3D point seen by both raw cameras lands on the same rectified row, at the disparity bf / z.
TEST(StereoRectifierTest, RawProjectionsMapToTheSameRow) {
  const EurocRig e = euroc_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const PinholeCamera cam0(e.cam0.camera), cam1(e.cam1.camera);
  const PinholeCamera rect(rectifier.rig().intrinsics);
  // Rectified pixel of a raw left/right pixel: undistort, back to a ray, rotate, project.
  const SO3 R_rect_cam0 = rectifier.R_cam0_rect().inverse();
  const SO3 R_rect_cam1 = R_rect_cam0 * e.T_c1_c2.so3();
  for (const Vec3& p_cam0 : {Vec3(0.3, 0.2, 3.0), Vec3(-0.5, -0.3, 5.0), Vec3(0.1, 0.4, 1.5)}) {
    const Vec3 p_cam1 = e.T_c1_c2.inverse() * p_cam0;
    const Vec2 raw_left = cam0.project_distorted(p_cam0);
    const Vec2 raw_right = cam1.project_distorted(p_cam1);
    const Vec2 left = rect.project(R_rect_cam0 * cam0.unproject(cam0.undistort(raw_left)));
    const Vec2 right = rect.project(R_rect_cam1 * cam1.unproject(cam1.undistort(raw_right)));
    EXPECT_NEAR(left.y(), right.y(), 1e-6);
    const double z_rect = (R_rect_cam0 * p_cam0).z();
    EXPECT_NEAR(left.x() - right.x(), rectifier.rig().disparity_from_depth(z_rect), 1e-6);
  }
}

struct VerticalOffsets {
  std::vector<double> dy;  // |y_left - y_right| of the inlier matches
  double median() const {
    std::vector<double> sorted = dy;
    std::sort(sorted.begin(), sorted.end());
    return sorted[sorted.size() / 2];
  }
  double fraction_below(double limit) const {
    return static_cast<double>(
               std::count_if(dy.begin(), dy.end(), [&](double d) { return d < limit; })) /
           static_cast<double>(dy.size());
  }
};

// ORB matches (cross-checked) filtered by a RANSAC fundamental matrix, which does not assume
// horizontal epipolar lines, so it keeps the correct matches of both raw and rectified pairs.
VerticalOffsets match_offsets(const cv::Mat& left, const cv::Mat& right) {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1500);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(left, cv::noArray(), kl, dl);
  orb->detectAndCompute(right, cv::noArray(), kr, dr);
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_HAMMING, true).match(dl, dr, matches);
  std::vector<cv::Point2f> pl, pr;
  for (const cv::DMatch& m : matches) {
    if (m.distance > 50) continue;
    pl.push_back(kl[static_cast<std::size_t>(m.queryIdx)].pt);
    pr.push_back(kr[static_cast<std::size_t>(m.trainIdx)].pt);
  }
  // ORB positions are quantised to the pixel grid of their pyramid level; refine them so that
  // the offsets measure the geometry, not the quantisation.
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  cv::cornerSubPix(left, pl, cv::Size(4, 4), cv::Size(-1, -1), criteria);
  cv::cornerSubPix(right, pr, cv::Size(4, 4), cv::Size(-1, -1), criteria);
  cv::setRNGSeed(1);
  std::vector<uchar> inlier;
  cv::findFundamentalMat(pl, pr, cv::FM_RANSAC, 1.0, 0.999, inlier);
  VerticalOffsets offsets;
  for (std::size_t i = 0; i < pl.size(); ++i)
    if (inlier[i]) offsets.dy.push_back(std::abs(pl[i].y - pr[i].y));
  return offsets;
}

TEST(StereoRectifierTest, RectifiedEurocPairHasHorizontalEpipolarLines) {
  const EurocRig e = euroc_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const std::string mav0 = test::euroc_fixture_dir() + "/mav0";
  // Frames 0, 40 and 94 of the clip.
  for (const std::string name :
       {"1403715273262142976.png", "1403715275262142976.png", "1403715277962142976.png"}) {
    SCOPED_TRACE(name);
    const cv::Mat raw_left = cv::imread(mav0 + "/cam0/data/" + name, cv::IMREAD_GRAYSCALE);
    const cv::Mat raw_right = cv::imread(mav0 + "/cam1/data/" + name, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(raw_left.empty());
    ASSERT_FALSE(raw_right.empty());
    cv::Mat left, right;
    rectifier.rectify(raw_left, raw_right, left, right);
    ASSERT_EQ(left.size(), raw_left.size());
    ASSERT_EQ(left.type(), CV_8UC1);

    const VerticalOffsets rectified = match_offsets(left, right);
    const VerticalOffsets raw = match_offsets(raw_left, raw_right);
    std::cout << "rectified: " << rectified.dy.size() << " inliers, median |dy| "
              << rectified.median() << " px, " << 100.0 * rectified.fraction_below(1.0)
              << "% < 1 px; raw: " << raw.dy.size() << " inliers, median |dy| " << raw.median()
              << " px, " << 100.0 * raw.fraction_below(1.0) << "% < 1 px\n";
    ASSERT_GE(rectified.dy.size(), 50u);
    ASSERT_GE(raw.dy.size(), 50u);
    EXPECT_LT(rectified.median(), 0.5);
    EXPECT_GE(rectified.fraction_below(1.0), 0.9);
    // Without rectification the rows disagree by several pixels (cy differs by ~7 px alone).
    EXPECT_GT(raw.median(), 3.0);
    EXPECT_LT(raw.fraction_below(1.0), 0.3);
  }
}

// The pixel of a rectified left image maps back to where the same 3D point appears in the raw
// cam0 image (stable_features.csv reports raw pixels).
TEST(StereoRectifierTest, RectifiedPixelsMapBackToRawLeftPixels) {
  const EurocRig e = euroc_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const PinholeCamera cam0(e.cam0.camera);
  const PinholeCamera rectified(rectifier.rig().intrinsics);
  for (const Vec3& p_cam0 :
       {Vec3(0.0, 0.0, 3.0), Vec3(-1.2, 0.7, 2.5), Vec3(1.5, -0.9, 4.0), Vec3(2.0, 1.2, 2.2)}) {
    const Vec2 raw = cam0.project_distorted(p_cam0);
    const Vec2 rect = rectified.project(rectifier.R_cam0_rect().inverse() * p_cam0);
    EXPECT_LT((rectifier.rectified_to_raw_left(rect) - raw).norm(), 1e-9) << raw.transpose();
  }
}

// TUM-VI's fisheye pair (ORB-SLAM3's TUM-VI settings): 512x512, Kannala-Brandt.
EurocRig tum_vi_rig() {
  EurocRig rig;
  for (CameraSettings* c : {&rig.cam0.camera, &rig.cam1.camera}) {
    c->model = CameraModel::kKannalaBrandt8;
    c->width = c->height = 512;
  }
  rig.cam0.camera.intrinsics = {190.978477, 190.973307, 254.931706, 256.897442};
  rig.cam0.camera.fisheye = {0.003482389402, 0.000715034845, -0.002053236141, 0.000202936736};
  rig.cam1.camera.intrinsics = {190.442369, 190.434387, 252.597621, 254.917213};
  rig.cam1.camera.fisheye = {0.003400720715, 0.001766761649, -0.002664001124, 0.000333748919};
  Mat4 T;
  T << 0.999994, 0.001079, -0.003218, 0.101160, -0.001067, 0.999994, 0.003498, 0.001983, 0.003222,
      -0.003494, 0.999989, 0.001045, 0, 0, 0, 1;
  T.topLeftCorner<3, 3>() = Eigen::Quaterniond(Mat3(T.topLeftCorner<3, 3>())).normalized().matrix();
  rig.T_c1_c2 = SE3::from_matrix(T);
  return rig;
}

// A Gaussian dot (sigma 1.5 px) centred on a sub-pixel position of a 512x512 image.
cv::Mat dot_image(const Vec2& centre) {
  cv::Mat image(512, 512, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const double d2 = (Vec2(x, y) - centre).squaredNorm();
      if (d2 < 36.0)
        image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(255.0 * std::exp(-d2 / 4.5));
    }
  return image;
}

// Intensity-weighted centre of the brightest blob: a dot's place to a fraction of a pixel.
Vec2 dot_centre(const cv::Mat& image) {
  cv::Point peak;
  cv::minMaxLoc(image, nullptr, nullptr, nullptr, &peak);
  double sum = 0.0, sx = 0.0, sy = 0.0;
  for (int y = std::max(0, peak.y - 4); y <= std::min(image.rows - 1, peak.y + 4); ++y)
    for (int x = std::max(0, peak.x - 4); x <= std::min(image.cols - 1, peak.x + 4); ++x) {
      const double w = image.at<std::uint8_t>(y, x);
      sum += w;
      sx += w * x;
      sy += w * y;
    }
  return {sx / sum, sy / sum};
}

// A dot drawn where a point appears in each raw fisheye image is found, after rectify(), where the
// rectified rig projects the point: on one row, at the disparity bf / z.
TEST(StereoRectifierTest, FisheyePairRectifiesOntoRows) {
  const EurocRig e = tum_vi_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const StereoRig& rig = rectifier.rig();
  EXPECT_NEAR(rig.baseline, e.T_c1_c2.translation().norm(), 1e-9);
  // OpenCV would fit the lens's whole view (61 px); the view stops 70 degrees off the axis.
  EXPECT_NEAR(rig.intrinsics.fx, 256.0 / std::tan(kMaxFisheyeFieldAngle), 1e-6);
  const PinholeCamera cam0(e.cam0.camera), cam1(e.cam1.camera);
  const PinholeCamera rect(rig.intrinsics);
  const SO3 R_rect_cam0 = rectifier.R_cam0_rect().inverse();
  // Up to 50 degrees off the axis, where a fisheye and a pinhole lens differ by 60 px; a dot
  // there is stretched, which moves its centroid by up to 0.3 px.
  for (const Vec3& p_cam0 : {Vec3(0.2, 0.1, 2.0), Vec3(-1.0, -0.6, 1.2), Vec3(0.9, 0.7, 1.0)}) {
    const Vec2 l = cam0.project_distorted(p_cam0);
    const Vec2 r = cam1.project_distorted(e.T_c1_c2.inverse() * p_cam0);
    cv::Mat left, right;
    rectifier.rectify(dot_image(l), dot_image(r), left, right);
    const Vec2 found_left = dot_centre(left), found_right = dot_centre(right);
    const Vec3 p_rect = R_rect_cam0 * p_cam0;
    const Vec2 expected_left = rect.project(p_rect);
    const Vec2 expected_right = rect.project(p_rect - Vec3(rig.baseline, 0.0, 0.0));
    EXPECT_LT((found_left - expected_left).norm(), 0.5) << p_cam0.transpose();
    EXPECT_LT((found_right - expected_right).norm(), 0.5) << p_cam0.transpose();
    EXPECT_NEAR(found_right.y(), found_left.y(), 0.5) << p_cam0.transpose();
    EXPECT_NEAR(expected_left.x() - expected_right.x(), rig.disparity_from_depth(p_rect.z()), 1e-9);
    // And back: the rectified pixel's raw place is the fisheye projection.
    EXPECT_LT((rectifier.rectified_to_raw_left(expected_left) - l).norm(), 1e-6);
  }
  Settings settings;
  settings.camera = e.cam0.camera;
  settings.stereo.right = e.cam1.camera;
  settings.stereo.T_c1_c2 = e.T_c1_c2;
  EXPECT_EQ(rectified_settings(settings, rectifier).camera.model, CameraModel::kPinhole);
  // A fisheye camera cannot be paired with a pinhole one.
  CameraSettings pinhole = e.cam1.camera;
  pinhole.model = CameraModel::kPinhole;
  EXPECT_THROW(StereoRectifier(e.cam0.camera, pinhole, e.T_c1_c2), Error);
}

TEST(StereoRectifierTest, RejectsBadInput) {
  const EurocRig e = euroc_rig();
  const StereoRectifier rectifier(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  cv::Mat out_l, out_r;
  const cv::Mat small(100, 100, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(rectifier.rectify(small, small, out_l, out_r), Error);
  EXPECT_THROW(rectifier.rectify(cv::Mat(), cv::Mat(), out_l, out_r), Error);
  EXPECT_THROW(StereoRectifier(e.cam0.camera, e.cam1.camera, SE3()), Error);
  CameraSettings other_size = e.cam1.camera;
  other_size.width = 640;
  EXPECT_THROW(StereoRectifier(e.cam0.camera, other_size, e.T_c1_c2), Error);
  EXPECT_THROW(StereoRectifier::from_settings(Settings{}), Error);
}

TEST(StereoRectifierTest, RectifiedSettings) {
  const EurocRig e = euroc_rig();
  Settings settings;
  settings.camera = e.cam0.camera;
  settings.stereo.enabled = true;
  settings.stereo.right = e.cam1.camera;
  settings.stereo.T_c1_c2 = e.T_c1_c2;
  const StereoRectifier rectifier = StereoRectifier::from_settings(settings);
  const Settings out = rectified_settings(settings, rectifier);
  EXPECT_FALSE(out.stereo.needs_rectification());
  EXPECT_TRUE(out.camera.distortion.is_zero());
  EXPECT_DOUBLE_EQ(out.camera.intrinsics.fx, rectifier.rig().intrinsics.fx);
  EXPECT_DOUBLE_EQ(out.stereo.bf, rectifier.rig().bf);
  EXPECT_DOUBLE_EQ(out.stereo.baseline, rectifier.rig().baseline);
}

// ORB-SLAM2's LEFT.* / RIGHT.* made by cv::stereoRectify at alpha 0, as our rectifier makes its
// own: the same rig, frame and images.
TEST(StereoRectifierTest, PrecomputedRectificationAtAlphaZeroIsOurOwn) {
  const EurocRig e = euroc_rig();
  const StereoRectifier ours(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  const StereoRectifier given(test::euroc_fixture_rectification(0.0));
  EXPECT_NEAR(given.rig().intrinsics.fx, ours.rig().intrinsics.fx, 1e-9);
  EXPECT_NEAR(given.rig().intrinsics.cy, ours.rig().intrinsics.cy, 1e-9);
  EXPECT_NEAR(given.rig().baseline, ours.rig().baseline, 1e-12);
  EXPECT_LT((given.R_cam0_rect().inverse() * ours.R_cam0_rect()).angle(), 1e-12);
  const std::string mav0 = test::euroc_fixture_dir() + "/mav0";
  const std::string name = "1403715275262142976.png";
  const cv::Mat raw_left = cv::imread(mav0 + "/cam0/data/" + name, cv::IMREAD_GRAYSCALE);
  const cv::Mat raw_right = cv::imread(mav0 + "/cam1/data/" + name, cv::IMREAD_GRAYSCALE);
  cv::Mat a_left, a_right, b_left, b_right;
  ours.rectify(raw_left, raw_right, a_left, a_right);
  given.rectify(raw_left, raw_right, b_left, b_right);
  EXPECT_EQ(cv::norm(a_left, b_left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a_right, b_right, cv::NORM_INF), 0.0);
}

// Another view (alpha 1 keeps every raw pixel): its own rig, and the pair still on common rows.
TEST(StereoRectifierTest, PrecomputedRectificationPutsTheEurocPairOnRows) {
  const PrecomputedRectification wide = test::euroc_fixture_rectification(1.0);
  const StereoRectifier rectifier(wide);
  const StereoRig& rig = rectifier.rig();
  EXPECT_DOUBLE_EQ(rig.intrinsics.fx, wide.left.P(0, 0));
  EXPECT_DOUBLE_EQ(rig.intrinsics.cx, wide.left.P(0, 2));
  EXPECT_DOUBLE_EQ(rig.bf, -wide.right.P(0, 3));
  EXPECT_NEAR(rig.baseline, 0.110078, 1e-6);
  const EurocRig e = euroc_rig();
  const StereoRectifier tight(e.cam0.camera, e.cam1.camera, e.T_c1_c2);
  EXPECT_LT(rig.intrinsics.fx, tight.rig().intrinsics.fx - 10.0);  // a wider view

  const std::string mav0 = test::euroc_fixture_dir() + "/mav0";
  const std::string name = "1403715277962142976.png";
  cv::Mat left, right;
  rectifier.rectify(cv::imread(mav0 + "/cam0/data/" + name, cv::IMREAD_GRAYSCALE),
                    cv::imread(mav0 + "/cam1/data/" + name, cv::IMREAD_GRAYSCALE), left, right);
  const VerticalOffsets offsets = match_offsets(left, right);
  ASSERT_GE(offsets.dy.size(), 50u);
  EXPECT_LT(offsets.median(), 0.5);
  EXPECT_GE(offsets.fraction_below(1.0), 0.9);

  // A rectified pixel maps back to where the raw cam0 image sees it, through LEFT.K, D and R.
  const PinholeCamera cam0(e.cam0.camera);
  const PinholeCamera rectified(rig.intrinsics);
  const Vec3 p_cam0(-1.2, 0.7, 2.5);
  const Vec2 rect = rectified.project(rectifier.R_cam0_rect().inverse() * p_cam0);
  EXPECT_LT((rectifier.rectified_to_raw_left(rect) - cam0.project_distorted(p_cam0)).norm(), 1e-9);
}

TEST(StereoRectifierTest, PrecomputedRectificationRejectsABadRig) {
  PrecomputedRectification rect = test::euroc_fixture_rectification(0.0);
  rect.right.raw.width = 640;
  EXPECT_THROW(StereoRectifier{rect}, Error);
  rect = test::euroc_fixture_rectification(0.0);
  rect.right.P(0, 3) = 0.0;  // no baseline
  EXPECT_THROW(StereoRectifier{rect}, Error);
}

}  // namespace
}  // namespace sbaslam
