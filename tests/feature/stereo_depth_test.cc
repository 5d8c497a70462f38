// Stereo depths of the ORB front end against an independent reference: a dense semi-global
// matcher on the rectified EuRoC fixture (no depth ground truth there), and the renderer's exact
// depth on the simulator's `straight` street.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <string>
#include <vector>

#include "helper/images.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/io/euroc_reader.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam::feature {
namespace {

const std::string kEuroc = std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro";

struct Errors {
  std::vector<double> relative;  // |Z - Z_ref| / Z_ref per compared keypoint
  int with_depth = 0;            // keypoints with a stereo depth, compared or not

  double quantile(double q) const {
    std::vector<double> sorted = relative;
    std::sort(sorted.begin(), sorted.end());
    return sorted.empty() ? 1.0 : sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
  }
};

// Every stereo depth must be the triangulation of its own disparity with the rig's baseline; the
// check keeps depth and u_right from drifting apart.
void expect_triangulated(const StereoFeatures& f, const StereoRig& rig) {
  for (std::size_t i = 0; i < f.left.size(); ++i) {
    const float z = f.matches.depth[i];
    if (z <= 0.0f) continue;
    const float disparity = f.left.keypoints[i].x - f.matches.u_right[i];
    ASSERT_GT(disparity, 0.0f);
    EXPECT_NEAR(z, rig.bf / disparity, 1e-3 * z);
  }
}

// Semi-global matching with subpixel disparity (1/16 px) and a left-right consistency check, so
// that its disparities are its own and trustworthy where it reports one.
cv::Mat semi_global_disparity(const cv::Mat& left, const cv::Mat& right) {
  const int block = 5;
  const auto sgbm = cv::StereoSGBM::create(0, 128, block, 8 * block * block, 32 * block * block,
                                           /*disp12MaxDiff=*/1, /*preFilterCap=*/31,
                                           /*uniquenessRatio=*/10, /*speckleWindowSize=*/100,
                                           /*speckleRange=*/2, cv::StereoSGBM::MODE_SGBM);
  cv::Mat disparity;
  sgbm->compute(left, right, disparity);
  return disparity;  // CV_16S, disparity * 16, negative where invalid
}

// EuRoC has no depth ground truth. The reference is cv::StereoSGBM on the same rectified pair: a
// dense method that shares nothing with ours (census-like cost, aggregation along 5 paths, no
// keypoints, no descriptors), so agreement is evidence, not an echo. The test fails if our
// disparities are wrong: a match taken from the wrong row or octave, a scale error between pyramid
// levels and level 0, a parabola fit biased by a pixel, or descriptor mismatches (these land on a
// different corner, tens of pixels away, far outside 10%). SGBM is itself wrong on some pixels,
// so the test asserts on the median and on a majority, not on every keypoint.
TEST(StereoDepth, EurocRectifiedDepthsAgreeWithSemiGlobalMatching) {
  const io::EurocReader reader(kEuroc);
  ASSERT_TRUE(reader.has_right());
  const StereoRig rig = reader.calibration()->stereo.value();
  StereoExtractor stereo(test::orb_settings_with(1200), rig);
  Errors errors;
  for (std::size_t frame : {0u, 47u, 94u}) {
    const io::FrameData data = reader.load(frame);
    const StereoFeatures f = stereo.extract(data.left, data.right);
    expect_triangulated(f, rig);
    const cv::Mat reference = semi_global_disparity(data.left, data.right);
    for (std::size_t i = 0; i < f.left.size(); ++i) {
      if (f.matches.depth[i] <= 0.0f) continue;
      ++errors.with_depth;
      const OrbKeypoint& kp = f.left.keypoints[i];
      const std::int16_t raw = reference.at<std::int16_t>(static_cast<int>(std::lround(kp.y)),
                                                          static_cast<int>(std::lround(kp.x)));
      if (raw <= 0) continue;  // SGBM has no (consistent) disparity here
      const double z_ref = rig.bf / (raw / 16.0);
      errors.relative.push_back(std::abs(f.matches.depth[i] - z_ref) / z_ref);
    }
  }
  const double median = errors.quantile(0.5);
  const double within_10 =
      static_cast<double>(std::count_if(errors.relative.begin(), errors.relative.end(),
                                        [](double e) { return e < 0.10; })) /
      static_cast<double>(std::max<std::size_t>(errors.relative.size(), 1));
  std::printf(
      "EuRoC stereo vs SGBM: %d keypoints with depth, %zu compared, median %.4f, "
      "p80 %.4f, within 10%% %.3f\n",
      errors.with_depth, errors.relative.size(), median, errors.quantile(0.8), within_10);
  ::testing::Test::RecordProperty("euroc_median_relative_depth_error", std::to_string(median));
  // Measured: 1779 compared, median 1.0%, 95% within 10%. With the raw SAD (ORB-SLAM3's, fooled
  // by the cameras' brightness difference) the same test gives 2.7% and 77% and fails.
  ASSERT_GT(errors.relative.size(), 1200u);
  EXPECT_LT(median, 0.02);
  EXPECT_GT(within_10, 0.90);
}

// The simulator's `straight` street renders the exact depth of every left pixel, so the error
// below is the front end's own (plus the renderer's sensor noise and motion blur, left on).
TEST(StereoDepth, StraightSceneDepthsMatchRenderedGroundTruth) {
  sim::SceneOptions options;
  options.name = "straight";
  const sim::Scene scene = sim::make_scene(options);
  const sim::ViewCamera& cam = scene.camera;
  const StereoRig rig(PinholeIntrinsics{cam.fx, cam.fy, cam.cx, cam.cy}, scene.baseline);
  StereoExtractor stereo(test::orb_settings_with(2000), rig);
  Errors errors;
  for (int index : {5, 40, 75}) {
    const sim::StereoFrame frame = sim::render_frame(scene, index);
    ASSERT_EQ(frame.left.size(), cv::Size(1241, 376));
    const StereoFeatures f = stereo.extract(frame.left, frame.right);
    expect_triangulated(f, rig);
    for (std::size_t i = 0; i < f.left.size(); ++i) {
      if (f.matches.depth[i] <= 0.0f) continue;
      ++errors.with_depth;
      const OrbKeypoint& kp = f.left.keypoints[i];
      const float z_gt = frame.depth.at<float>(static_cast<int>(std::lround(kp.y)),
                                               static_cast<int>(std::lround(kp.x)));
      if (z_gt <= 0.0f || z_gt > 20.0f) continue;  // sky, or beyond the 20 m of the issue
      errors.relative.push_back(std::abs(f.matches.depth[i] - z_gt) / z_gt);
    }
  }
  const double median = errors.quantile(0.5);
  std::printf("straight scene: %d keypoints with depth, %zu within 20 m, median %.4f, p80 %.4f\n",
              errors.with_depth, errors.relative.size(), median, errors.quantile(0.8));
  ::testing::Test::RecordProperty("straight_median_relative_depth_error", std::to_string(median));
  ASSERT_GT(errors.relative.size(), 300u);
  EXPECT_LT(median, 0.02);
}

}  // namespace
}  // namespace sbaslam::feature
