#pragma once
// Rectification of an unrectified stereo rig (EuRoC, ORB-SLAM3 v1.0 "Camera2" + "Stereo.T_c1_c2"):
// cv::stereoRectify (alpha 0, CALIB_ZERO_DISPARITY) and cv::initUndistortRectifyMap run once in
// the constructor; rectify() only remaps. ORB-SLAM2's files may give the rectification itself
// (LEFT.* / RIGHT.*), which then replaces cv::stereoRectify. A Kannala-Brandt pair (TUM-VI,
// ORB-SLAM3's "KannalaBrandt8") goes through their cv::fisheye versions instead, into a pinhole
// view that reaches at most kMaxFisheyeFieldAngle off the axis.
//
// Frames: the rectified left camera shares its optical centre with the original left camera
// (cam0) but is rotated by R_cam0_rect. SLAM on rectified images estimates poses of the rectified
// camera, T_world_rect; the pose of cam0 is T_world_rect * T_rect_cam0(). Report trajectories in
// cam0's frame.

#include <opencv2/core.hpp>

#include "sbaslam/core/camera.h"
#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"

namespace sbaslam {

class StereoRectifier {
 public:
  // T_c1_c2 maps right-camera points into the left camera's frame (for EuRoC:
  // inv(T_BS_cam0) * T_BS_cam1). Both cameras must have the same, positive image size. Throws
  // sbaslam::Error on a degenerate rig.
  StereoRectifier(const CameraSettings& left, const CameraSettings& right, const SE3& T_c1_c2);
  // ORB-SLAM2's precomputed rectification (LEFT.* / RIGHT.*), remapped as its stereo_euroc
  // example does: each raw camera undistorted, rotated by its R and projected by its P.
  explicit StereoRectifier(const PrecomputedRectification& rectification);
  // From settings whose stereo.precomputed or stereo.right is set (throws otherwise).
  static StereoRectifier from_settings(const Settings& settings);

  // Remaps a raw pair (8-bit, the calibrated size; throws sbaslam::Error otherwise).
  void rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_rectified,
               cv::Mat& right_rectified) const;

  // Rig of the rectified images: shared intrinsics, no distortion, baseline along +x.
  const StereoRig& rig() const { return rig_; }
  cv::Size image_size() const { return size_; }
  // Rotation of the rectified left frame expressed in cam0: p_cam0 = R_cam0_rect * p_rect.
  const SO3& R_cam0_rect() const { return R_cam0_rect_; }
  // Pose of cam0 in the rectified left frame (pure rotation): T_world_cam0 =
  // T_world_rect * T_rect_cam0().
  SE3 T_rect_cam0() const { return SE3(R_cam0_rect_.inverse(), Vec3::Zero()); }
  SE3 T_cam0_rect() const { return SE3(R_cam0_rect_, Vec3::Zero()); }
  // Pixel of the rectified left image -> where it lies in the raw (distorted, unrotated) left
  // image; the inverse of rectify()'s remapping of the left image.
  Vec2 rectified_to_raw_left(const Vec2& rectified) const;

 private:
  // The rig and the maps from the rotations into the rectified frames and the projections there.
  void set_up(const PinholeCamera& right, const cv::Mat& R1, const cv::Mat& R2, const cv::Mat& P1,
              const cv::Mat& P2, const char* hint);

  cv::Size size_;
  PinholeCamera left_;
  StereoRig rig_;
  SO3 R_cam0_rect_;
  cv::Mat left_map1_, left_map2_, right_map1_, right_map2_;
};

// The settings of the rectified images: camera intrinsics replaced by the rectified ones, no
// distortion, stereo baseline and bf filled, stereo.right cleared.
Settings rectified_settings(const Settings& settings, const StereoRectifier& rectifier);

}  // namespace sbaslam
