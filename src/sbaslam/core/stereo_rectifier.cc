#include "sbaslam/core/stereo_rectifier.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

namespace sbaslam {
namespace {

cv::Mat to_cv(const Mat3& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = m(r, c);
  return out;
}

Mat3 to_eigen(const cv::Mat& m) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m.at<double>(r, c);
  return out;
}

void check_image(const cv::Mat& image, cv::Size expected, const char* which) {
  if (image.empty()) fail("stereo rectification: the {} image is empty", which);
  if (image.size() != expected)
    fail("stereo rectification: the {} image is {}x{}, the calibration is for {}x{}", which,
         image.cols, image.rows, expected.width, expected.height);
  if (image.depth() != CV_8U) fail("stereo rectification: the {} image is not 8-bit", which);
}

// cv::stereoRectify's outputs: the rotations into the rectified frames and the projections.
struct Rectification {
  cv::Mat R1, R2, P1, P2;
};

Rectification rectify_pair(const PinholeCamera& left, const PinholeCamera& right, cv::Size size,
                           const SE3& T_c1_c2) {
  // OpenCV wants the motion taking left-camera points into the right camera.
  const SE3 T_c2_c1 = T_c1_c2.inverse();
  const cv::Mat R = to_cv(T_c2_c1.rotation());
  const cv::Mat t = (cv::Mat_<double>(3, 1) << T_c2_c1.translation().x(), T_c2_c1.translation().y(),
                     T_c2_c1.translation().z());
  const cv::Mat K1(left.K()), K2(right.K());
  Rectification r;
  cv::Mat Q;
  if (!left.is_fisheye()) {
    cv::stereoRectify(K1, left.dist_coeffs(), K2, right.dist_coeffs(), size, R, t, r.R1, r.R2, r.P1,
                      r.P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0, size);
    return r;
  }
  // OpenCV fits the whole valid view into the image (balance 0), as cv::stereoRectify does with
  // alpha 0 above. For a lens wider than the pinhole plane can hold that shrinks the focal length
  // without bound (TUM-VI's 190 px became 61 px), so the view stops where the image's edges are
  // kMaxFisheyeFieldAngle off the axis, the limit monocular fisheye keypoints have too (93 px for
  // TUM-VI's 512 px). On the fisheye room (corners 56 degrees off the axis) OpenCV's own choice,
  // 413 px, gave 8.7 mm of ATE and the raw focal length, 459 px, 11 mm: the wider view wins.
  const auto rectify = [&](double fov_scale) {
    cv::fisheye::stereoRectify(K1, left.dist_coeffs(), K2, right.dist_coeffs(), size, R, t, r.R1,
                               r.R2, r.P1, r.P2, Q, cv::CALIB_ZERO_DISPARITY, size, 0.0, fov_scale);
  };
  rectify(1.0);
  const double fitted_fx = r.P1.at<double>(0, 0);
  const double least_fx = 0.5 * std::max(size.width, size.height) / std::tan(kMaxFisheyeFieldAngle);
  if (std::isfinite(fitted_fx) && fitted_fx > 0.0 && fitted_fx < least_fx)
    rectify(fitted_fx / least_fx);
  return r;
}

void make_rectify_map(const PinholeCamera& camera, const cv::Mat& R, const cv::Mat& P,
                      cv::Size size, cv::Mat& map1, cv::Mat& map2) {
  if (camera.is_fisheye()) {
    cv::fisheye::initUndistortRectifyMap(camera.K(), camera.dist_coeffs(), R, P, size, CV_16SC2,
                                         map1, map2);
  } else {
    cv::initUndistortRectifyMap(camera.K(), camera.dist_coeffs(), R, P, size, CV_16SC2, map1, map2);
  }
}

}  // namespace

StereoRectifier::StereoRectifier(const CameraSettings& left, const CameraSettings& right,
                                 const SE3& T_c1_c2)
    : size_(left.width, left.height), left_(left) {
  if (left.width <= 0 || left.height <= 0)
    fail("stereo rectification: invalid image size {}x{}", left.width, left.height);
  if (right.width != left.width || right.height != left.height)
    fail("stereo rectification: left ({}x{}) and right ({}x{}) image sizes differ", left.width,
         left.height, right.width, right.height);
  if (!(T_c1_c2.translation().norm() > 0.0))
    fail("stereo rectification: zero baseline between the two cameras");

  const PinholeCamera cam_left(left), cam_right(right);
  if (cam_left.is_fisheye() != cam_right.is_fisheye())
    fail("stereo rectification: one camera is a fisheye (KannalaBrandt8) and the other is not");
  const Rectification r = rectify_pair(cam_left, cam_right, size_, T_c1_c2);
  set_up(cam_right, r.R1, r.R2, r.P1, r.P2,
         "is T_c1_c2 the pose of the right camera in the left one?");
}

StereoRectifier::StereoRectifier(const PrecomputedRectification& rectification)
    : size_(rectification.left.raw.width, rectification.left.raw.height),
      left_(rectification.left.raw) {
  const CameraSettings& right = rectification.right.raw;
  if (size_.width <= 0 || size_.height <= 0 || right.width != size_.width ||
      right.height != size_.height)
    fail("stereo rectification: LEFT ({}x{}) and RIGHT ({}x{}) image sizes differ or are empty",
         size_.width, size_.height, right.width, right.height);
  const auto to_cv_34 = [](const Mat34& m) {
    cv::Mat out(3, 4, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out.at<double>(r, c) = m(r, c);
    return out;
  };
  set_up(PinholeCamera(right), to_cv(rectification.left.R), to_cv(rectification.right.R),
         to_cv_34(rectification.left.P), to_cv_34(rectification.right.P),
         "RIGHT.P must hold -fx times the baseline");
}

void StereoRectifier::set_up(const PinholeCamera& right, const cv::Mat& R1, const cv::Mat& R2,
                             const cv::Mat& P1, const cv::Mat& P2, const char* hint) {
  const double fx = P1.at<double>(0, 0);
  const double baseline = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  if (!std::isfinite(fx) || !(fx > 0.0) || !std::isfinite(baseline) || !(baseline > 0.0))
    fail("stereo rectification failed: fx {}, baseline {} ({})", fx, baseline, hint);
  rig_ = StereoRig({fx, P1.at<double>(1, 1), P1.at<double>(0, 2), P1.at<double>(1, 2)}, baseline);
  // R1 takes cam0 points into the rectified frame.
  R_cam0_rect_ = SO3::from_matrix(to_eigen(R1).transpose());
  make_rectify_map(left_, R1, P1, size_, left_map1_, left_map2_);
  make_rectify_map(right, R2, P2, size_, right_map1_, right_map2_);
}

Vec2 StereoRectifier::rectified_to_raw_left(const Vec2& rectified) const {
  const PinholeIntrinsics& k = rig_.intrinsics;
  const Vec3 ray_rect((rectified.x() - k.cx) / k.fx, (rectified.y() - k.cy) / k.fy, 1.0);
  return left_.project_distorted(R_cam0_rect_ * ray_rect);
}

StereoRectifier StereoRectifier::from_settings(const Settings& settings) {
  if (settings.stereo.precomputed) return StereoRectifier(*settings.stereo.precomputed);
  if (!settings.stereo.right)
    fail("{}: no second camera (Camera2.* and Stereo.T_c1_c2, or LEFT.* and RIGHT.*) to rectify",
         settings.path);
  return StereoRectifier(settings.camera, *settings.stereo.right, settings.stereo.T_c1_c2);
}

void StereoRectifier::rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_rectified,
                              cv::Mat& right_rectified) const {
  check_image(left, size_, "left");
  check_image(right, size_, "right");
  cv::remap(left, left_rectified, left_map1_, left_map2_, cv::INTER_LINEAR);
  cv::remap(right, right_rectified, right_map1_, right_map2_, cv::INTER_LINEAR);
}

Settings rectified_settings(const Settings& settings, const StereoRectifier& rectifier) {
  Settings out = settings;
  out.camera.intrinsics = rectifier.rig().intrinsics;
  out.camera.model = CameraModel::kPinhole;
  out.camera.distortion = RadTanDistortion{};
  out.camera.fisheye = KannalaBrandtDistortion{};
  out.stereo.enabled = true;
  out.stereo.baseline = rectifier.rig().baseline;
  out.stereo.bf = rectifier.rig().bf;
  out.stereo.right.reset();
  out.stereo.precomputed.reset();
  out.stereo.T_c1_c2 = SE3(SO3(), Vec3(rectifier.rig().baseline, 0.0, 0.0));
  return out;
}

}  // namespace sbaslam
