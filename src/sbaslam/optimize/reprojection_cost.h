#pragma once
// Ceres reprojection residuals of ORB-SLAM's BA, for a pose stored as [qx qy qz qw tx ty tz]
// (T_cw: world to camera) and a world point. The residual is scaled by sqrt(weight / sigma^2), so
// the robust loss sees w * e^T Sigma^-1 e: the Salient BA cost of the paper, with weight 1 giving
// ORB-SLAM's cost. Observations are undistorted, rectified pixel coordinates.

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "sbaslam/core/settings.h"

namespace sbaslam::optimize {

// A rectified pinhole camera; bf (baseline times fx) is only used by stereo residuals.
struct RectifiedCamera {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0, bf = 0.0;
};

// One image measurement of a point. u_right < 0 means a monocular observation.
struct PixelObservation {
  double u = 0.0, v = 0.0;
  double u_right = -1.0;
  double inv_sigma2 = 1.0;  // 1 / sigma^2 of the keypoint's pyramid level
  double weight = 1.0;      // the observation's BA weight (saliency), from one place
  bool is_stereo() const { return u_right >= 0.0; }
};

// Residual scale sqrt(weight * inv_sigma2); kept in one place so every BA agrees.
inline double residual_scale(const PixelObservation& obs) {
  return std::sqrt(obs.weight * obs.inv_sigma2);
}

template <typename T>
void transform_to_camera(const T* pose, const T* point, T* p_cam) {
  // Eigen quaternion memory order is x y z w; ceres::QuaternionRotatePoint wants w x y z.
  const T q_wxyz[4] = {pose[3], pose[0], pose[1], pose[2]};
  ceres::QuaternionRotatePoint(q_wxyz, point, p_cam);
  p_cam[0] += pose[4];
  p_cam[1] += pose[5];
  p_cam[2] += pose[6];
}

struct MonoReprojectionCost {
  MonoReprojectionCost(const RectifiedCamera& cam, const PixelObservation& obs)
      : cam_(cam), obs_(obs), scale_(residual_scale(obs)) {}

  template <typename T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    T p[3];
    transform_to_camera(pose, point, p);
    const T inv_z = T(1.0) / p[2];
    residual[0] = scale_ * (T(obs_.u) - (cam_.fx * p[0] * inv_z + cam_.cx));
    residual[1] = scale_ * (T(obs_.v) - (cam_.fy * p[1] * inv_z + cam_.cy));
    return true;
  }

  static ceres::CostFunction* create(const RectifiedCamera& cam, const PixelObservation& obs) {
    return new ceres::AutoDiffCostFunction<MonoReprojectionCost, 2, 7, 3>(
        new MonoReprojectionCost(cam, obs));
  }

  RectifiedCamera cam_;
  PixelObservation obs_;
  double scale_;
};

struct StereoReprojectionCost {
  StereoReprojectionCost(const RectifiedCamera& cam, const PixelObservation& obs)
      : cam_(cam), obs_(obs), scale_(residual_scale(obs)) {}

  template <typename T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    T p[3];
    transform_to_camera(pose, point, p);
    const T inv_z = T(1.0) / p[2];
    const T u = cam_.fx * p[0] * inv_z + cam_.cx;
    residual[0] = scale_ * (T(obs_.u) - u);
    residual[1] = scale_ * (T(obs_.v) - (cam_.fy * p[1] * inv_z + cam_.cy));
    residual[2] = scale_ * (T(obs_.u_right) - (u - cam_.bf * inv_z));
    return true;
  }

  static ceres::CostFunction* create(const RectifiedCamera& cam, const PixelObservation& obs) {
    return new ceres::AutoDiffCostFunction<StereoReprojectionCost, 3, 7, 3>(
        new StereoReprojectionCost(cam, obs));
  }

  RectifiedCamera cam_;
  PixelObservation obs_;
  double scale_;
};

// Unweighted chi-square statistic e^T Sigma^-1 e of an observation, and whether the point lies in
// front of the camera. Outlier tests use this unweighted value: the chi-square thresholds (5.991,
// 7.815) describe the distribution of the unweighted error, and a weight must not make a salient
// point easier (or a non-salient one harder) to reject.
struct ReprojectionCheck {
  double chi2 = 0.0;
  bool in_front = false;
};

ReprojectionCheck check_reprojection(const RectifiedCamera& cam, const double* pose_qt,
                                     const double* point, const PixelObservation& obs);

// Chi-square thresholds at 95% for 2 and 3 degrees of freedom, as ORB-SLAM.
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.815;

}  // namespace sbaslam::optimize
