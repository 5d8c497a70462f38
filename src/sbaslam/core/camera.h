#pragma once
// Pinhole camera with radial-tangential (OpenCV "plumb bob") or Kannala-Brandt fisheye distortion,
// and the rectified stereo rig of ORB-SLAM (fx, fy, cx, cy, baseline, bf). Called per keypoint in
// tracking: everything is inline-cheap, no allocation.
//
// Pixel conventions: a "distorted" pixel is where a point appears in the raw image; an
// "undistorted" pixel is where an ideal pinhole camera with the same K would see it. Everything
// after keypoint undistortion works on undistorted pixels, so a fisheye camera is handled as a
// pinhole one from there on; that is why it cannot see rays at 90 degrees or more from its axis
// (see kMaxFisheyeFieldAngle).

#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"

namespace sbaslam {

// A fisheye keypoint further than this from the optical axis is not used: on the pinhole plane its
// position grows as tan(theta) and its pixel noise as 1/cos^2(theta), 8.5 times the noise at the
// image centre at 70 degrees and without bound towards 90. ORB-SLAM3 keeps the fisheye model
// through BA instead.
constexpr double kMaxFisheyeFieldAngle = 70.0 * M_PI / 180.0;

class PinholeCamera {
 public:
  PinholeCamera() = default;
  PinholeCamera(const PinholeIntrinsics& intrinsics, const RadTanDistortion& distortion = {});
  PinholeCamera(const PinholeIntrinsics& intrinsics, const KannalaBrandtDistortion& fisheye);
  explicit PinholeCamera(const CameraSettings& settings);

  const PinholeIntrinsics& intrinsics() const { return k_; }
  CameraModel model() const { return model_; }
  const RadTanDistortion& distortion() const { return d_; }
  const KannalaBrandtDistortion& fisheye() const { return f_; }
  bool has_distortion() const { return has_distortion_; }
  bool is_fisheye() const { return model_ == CameraModel::kKannalaBrandt8; }

  // Undistorted pixel of a point in the camera frame (z > 0 expected; the caller checks depth).
  Vec2 project(const Vec3& p_c) const {
    const double inv_z = 1.0 / p_c.z();
    return {k_.fx * p_c.x() * inv_z + k_.cx, k_.fy * p_c.y() * inv_z + k_.cy};
  }
  // Jacobian of project() with respect to p_c.
  Eigen::Matrix<double, 2, 3> project_jacobian(const Vec3& p_c) const;
  // Raw-image pixel of a point in the camera frame.
  Vec2 project_distorted(const Vec3& p_c) const { return distort(project(p_c)); }
  // Unit bearing vector of an undistorted pixel.
  Vec3 unproject(const Vec2& uv) const {
    return Vec3((uv.x() - k_.cx) / k_.fx, (uv.y() - k_.cy) / k_.fy, 1.0).normalized();
  }
  // Point on the normalised plane z = 1 of an undistorted pixel.
  Vec2 normalized(const Vec2& uv) const {
    return {(uv.x() - k_.cx) / k_.fx, (uv.y() - k_.cy) / k_.fy};
  }

  // Undistorted pixel -> raw pixel.
  Vec2 distort(const Vec2& uv) const;
  // Raw pixel -> undistorted pixel, by Gauss-Newton on distort(); agrees with a converged
  // cv::undistortPoints (P = K) to well below 1e-6 px inside the image. A fisheye pixel must lie
  // within field_angle() < 90 degrees.
  Vec2 undistort(const Vec2& uv_distorted) const;
  void undistort(std::vector<cv::Point2f>& points) const;
  // Angle between the optical axis and the ray of a raw pixel (fisheye: may exceed 90 degrees).
  double field_angle(const Vec2& uv_distorted) const;
  // undistort(), with a fisheye ray beyond kMaxFisheyeFieldAngle brought back to it.
  Vec2 undistort_within_field(const Vec2& uv_distorted) const;
  // Whether the ray of a raw pixel is within kMaxFisheyeFieldAngle (always, without fisheye).
  bool sees_on_pinhole_plane(const Vec2& uv_distorted) const {
    return !is_fisheye() || field_angle(uv_distorted) <= kMaxFisheyeFieldAngle;
  }

  cv::Matx33d K() const { return {k_.fx, 0.0, k_.cx, 0.0, k_.fy, k_.cy, 0.0, 0.0, 1.0}; }
  // OpenCV order: k1, k2, p1, p2, k3; for a fisheye camera cv::fisheye's k1, k2, k3, k4.
  cv::Mat dist_coeffs() const;

 private:
  // Distortion on the normalised plane, with its 2x2 Jacobian when `jacobian` is non-null.
  Vec2 distort_normalized(const Vec2& xy, Eigen::Matrix2d* jacobian) const;
  // Kannala-Brandt: the distorted radius theta_d of a ray at angle theta, and its inverse.
  double fisheye_radius(double theta) const;
  double fisheye_angle(double theta_d) const;

  PinholeIntrinsics k_;
  CameraModel model_ = CameraModel::kPinhole;
  RadTanDistortion d_;
  KannalaBrandtDistortion f_;
  bool has_distortion_ = false;
};

// A rectified stereo pair (or an RGB-D camera seen as one, as in ORB-SLAM): both images share
// the intrinsics and the right camera sits `baseline` metres along +x of the left one.
struct StereoRig {
  PinholeIntrinsics intrinsics;
  double baseline = 0.0;  // metres
  double bf = 0.0;        // baseline * fx, pixels * metres

  StereoRig() = default;
  StereoRig(const PinholeIntrinsics& k, double baseline_m)
      : intrinsics(k), baseline(baseline_m), bf(baseline_m * k.fx) {}

  // Column of a left-camera point at depth z in the right image: uR = u - bf / z.
  double right_u(double u, double z) const { return u - bf / z; }
  // Depth of a disparity d = uL - uR > 0.
  double depth_from_disparity(double disparity) const { return bf / disparity; }
  double disparity_from_depth(double z) const { return bf / z; }
  // Left-camera point of a left pixel with a known depth.
  Vec3 backproject(const Vec2& uv, double z) const {
    return {(uv.x() - intrinsics.cx) * z / intrinsics.fx,
            (uv.y() - intrinsics.cy) * z / intrinsics.fy, z};
  }
  // Left-camera point of a stereo match (uL, v) <-> uR; the disparity must be positive.
  Vec3 triangulate(const Vec2& uv_left, double u_right) const {
    return backproject(uv_left, depth_from_disparity(uv_left.x() - u_right));
  }
};

}  // namespace sbaslam
