#include "sbaslam/tracking/relocalizer.h"

#include <opencv2/calib3d.hpp>

#include "sbaslam/match/orb_matcher.h"
#include "sbaslam/tracking/frame_pose.h"
#include "sbaslam/tracking/projection.h"

namespace sbaslam::tracking {
namespace {

cv::Mat camera_matrix(const map::CameraRig& rig) {
  const PinholeIntrinsics& k = rig.camera.intrinsics();
  return (cv::Mat_<double>(3, 3) << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0);
}

SE3 to_se3(const cv::Mat& rvec, const cv::Mat& tvec) {
  const Vec3 r(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2));
  const Vec3 t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return SE3(SO3::exp(r), t);
}

int count_inliers(const SE3& T_cw, const std::vector<Vec3>& points, const std::vector<Vec2>& pixels,
                  const std::vector<int>& levels, const map::CameraRig& rig, double chi2,
                  std::vector<char>& inlier) {
  int count = 0;
  inlier.assign(points.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = T_cw * points[i];
    if (p.z() <= 0.0) continue;
    const double e2 = (rig.camera.project(p) - pixels[i]).squaredNorm() *
                      rig.levels.inv_sigma2[static_cast<std::size_t>(levels[i])];
    if (e2 < chi2) {
      inlier[i] = 1;
      ++count;
    }
  }
  return count;
}

}  // namespace

PnpResult solve_pnp_ransac(const std::vector<Vec3>& points_world, const std::vector<Vec2>& pixels,
                           const std::vector<int>& levels, const map::CameraRig& rig,
                           const PnpRansacOptions& options, std::mt19937_64& rng) {
  PnpResult best;
  const std::size_t n = points_world.size();
  if (n < 4 || static_cast<int>(n) < options.min_inliers) return best;
  const cv::Mat K = camera_matrix(rig);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  std::vector<cv::Point3d> object(4);
  std::vector<cv::Point2d> image(4);
  std::vector<char> inlier;
  for (int it = 0; it < options.iterations; ++it) {
    std::size_t idx[4];
    for (int k = 0; k < 4; ++k) {
      bool repeated = true;
      while (repeated) {
        idx[k] = pick(rng);
        repeated = false;
        for (int j = 0; j < k; ++j) repeated = repeated || idx[j] == idx[k];
      }
      object[static_cast<std::size_t>(k)] = {points_world[idx[k]].x(), points_world[idx[k]].y(),
                                             points_world[idx[k]].z()};
      image[static_cast<std::size_t>(k)] = {pixels[idx[k]].x(), pixels[idx[k]].y()};
    }
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(object, image, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_AP3P))
      continue;
    const SE3 T = to_se3(rvec, tvec);
    const int count =
        count_inliers(T, points_world, pixels, levels, rig, options.chi2_threshold, inlier);
    if (count > best.inliers) {
      best.inliers = count;
      best.T_cw = T;
      best.inlier = inlier;
    }
  }
  if (best.inliers < options.min_inliers) return PnpResult{};

  // Refine on all inliers, starting from the best minimal solution.
  std::vector<cv::Point3d> in_object;
  std::vector<cv::Point2d> in_image;
  for (std::size_t i = 0; i < n; ++i) {
    if (!best.inlier[i]) continue;
    in_object.emplace_back(points_world[i].x(), points_world[i].y(), points_world[i].z());
    in_image.emplace_back(pixels[i].x(), pixels[i].y());
  }
  cv::Mat rvec(3, 1, CV_64F), tvec(3, 1, CV_64F);
  const Vec3 r0 = best.T_cw.so3().log();
  for (int k = 0; k < 3; ++k) {
    rvec.at<double>(k) = r0[k];
    tvec.at<double>(k) = best.T_cw.translation()[k];
  }
  if (cv::solvePnP(in_object, in_image, K, cv::noArray(), rvec, tvec, true,
                   cv::SOLVEPNP_ITERATIVE)) {
    const SE3 refined = to_se3(rvec, tvec);
    const int count =
        count_inliers(refined, points_world, pixels, levels, rig, options.chi2_threshold, inlier);
    if (count >= best.inliers) {
      best.T_cw = refined;
      best.inliers = count;
      best.inlier = inlier;
    }
  }
  best.success = true;
  return best;
}

bool Relocalizer::relocalize(Frame& frame, const std::vector<map::KeyFrame*>& candidates,
                             const PoseCheck& accept) {
  for (map::KeyFrame* kf : candidates) {
    if (!kf || kf->is_bad() || !try_keyframe(frame, *kf)) continue;
    if (!accept || accept(frame.T_cw)) return true;
    ++refused_;
  }
  return false;
}

bool Relocalizer::try_keyframe(Frame& frame, map::KeyFrame& kf) {
  const std::vector<PointMatch> matches = match_keyframe_points_by_descriptor(kf, frame, 0.75f);
  if (matches.size() < 15) return false;

  std::vector<Vec3> points;
  std::vector<Vec2> pixels;
  std::vector<int> levels;
  for (const PointMatch& m : matches) {
    const feature::OrbKeypoint& kp = frame.m().keypoints_un[m.keypoint];
    points.push_back(m.point->position());
    pixels.emplace_back(kp.x, kp.y);
    levels.push_back(kp.octave);
  }
  const PnpResult pnp = solve_pnp_ransac(points, pixels, levels, rig_, PnpRansacOptions{}, rng_);
  if (!pnp.success) return false;

  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
  for (std::size_t j = 0; j < matches.size(); ++j)
    if (pnp.inlier[j]) frame.map_points[matches[j].keypoint] = matches[j].point;
  frame.set_pose(pnp.T_cw);
  int inliers = optimize_frame_pose(frame, rig_);
  if (inliers < 10) return false;
  frame.discard_outliers();
  if (inliers < 50) {
    search_from_keyframe(frame, kf, rig_, 10.0f, 100);
    inliers = optimize_frame_pose(frame, rig_);
    frame.discard_outliers();
  }
  return inliers >= 50;
}

}  // namespace sbaslam::tracking
