#include "sbaslam/feature/stereo_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "helper/images.h"
#include "sbaslam/core/error.h"

namespace sbaslam::feature {
namespace {

const std::string kPairs = std::string(SBASLAM_SHARED_DIR) + "/data/stereo_pairs";

using test::read_gray;

OrbSettings settings_with(int n_features) {
  return test::orb_settings_with(n_features);
}

// KITTI stereo 2015 training calibration: fx = 721.5377 px, baseline 0.5372 m. The depth error
// relative to the ground truth does not depend on bf: |Z - Z_gt| / Z_gt = |d_gt - d| / d.
const StereoRig kKitti2015Rig(PinholeIntrinsics{721.5377, 721.5377, 609.5593, 172.854}, 0.5372);

TEST(StereoMatcher, DepthsMatchKitti2015GroundTruth) {
  const cv::Mat left = read_gray(kPairs + "/kitti2015_000046/left.png");
  const cv::Mat right = read_gray(kPairs + "/kitti2015_000046/right.png");
  const cv::Mat gt = cv::imread(kPairs + "/kitti2015_000046/disp_occ.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(gt.type(), CV_16U);
  StereoExtractor stereo(settings_with(2000), kKitti2015Rig);
  const StereoFeatures f = stereo.extract(left, right);
  ASSERT_EQ(f.matches.depth.size(), f.left.size());

  std::vector<double> errors;
  int with_depth = 0;
  for (std::size_t i = 0; i < f.left.size(); ++i) {
    const float z = f.matches.depth[i];
    if (z <= 0.0f) {
      EXPECT_EQ(f.matches.u_right[i], -1.0f);
      continue;
    }
    ++with_depth;
    const OrbKeypoint& kp = f.left.keypoints[i];
    EXPECT_NEAR(z, kKitti2015Rig.bf / (kp.x - f.matches.u_right[i]), 1e-3 * z);
    const std::uint16_t raw = gt.at<std::uint16_t>(static_cast<int>(std::lround(kp.y)),
                                                   static_cast<int>(std::lround(kp.x)));
    if (raw == 0) continue;  // no ground truth here
    const double z_gt = kKitti2015Rig.bf / (raw / 256.0);
    if (z_gt > 20.0) continue;
    errors.push_back(std::abs(z - z_gt) / z_gt);
  }
  ASSERT_GT(errors.size(), 100u) << with_depth << " keypoints with depth";
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2];
  const double p80 = errors[errors.size() * 8 / 10];
  EXPECT_LT(median, 0.02) << errors.size() << " keypoints within 20 m";
  std::printf("KITTI 2015: %zu keypoints with GT within 20 m, median %.4f, p80 %.4f\n",
              errors.size(), median, p80);
  EXPECT_LT(p80, 0.05);
}

TEST(StereoMatcher, ParallelExtractionEqualsSequential) {
  const cv::Mat left = read_gray(kPairs + "/kitti06_frame12/left.png");
  const cv::Mat right = read_gray(kPairs + "/kitti06_frame12/right.png");
  const StereoRig rig(PinholeIntrinsics{707.0912, 707.0912, 601.8873, 183.1104},
                      379.8145 / 707.0912);
  StereoExtractor stereo(settings_with(2000), rig);
  const StereoFeatures parallel = stereo.extract(left, right);

  OrbExtractor l(settings_with(2000)), r(settings_with(2000));
  const OrbFeatures fl = l.extract(left), fr = r.extract(right);
  const StereoMatches sequential = match_stereo(fl, fr, l.pyramid(), r.pyramid(), l.levels(), rig);
  ASSERT_EQ(parallel.right.size(), fr.size());
  EXPECT_EQ(cv::norm(parallel.right.descriptors, fr.descriptors, cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(parallel.matches.depth, sequential.depth);
  EXPECT_EQ(parallel.matches.u_right, sequential.u_right);
  // A textured street: most keypoints find a stereo match, at a plausible depth.
  EXPECT_GT(parallel.matches.count(), static_cast<int>(parallel.left.size() / 2));
  for (float z : parallel.matches.depth)
    if (z > 0.0f) {
      EXPECT_GE(z, rig.baseline * 0.99);
    }
}

// A task run beside (the saliency inference) turns the extraction into per-level tasks: same
// keypoints, descriptors and matches, and the task ran once.
TEST(StereoMatcher, ExtractionWithATaskBesideEqualsWithout) {
  const cv::Mat left = read_gray(kPairs + "/kitti06_frame12/left.png");
  const cv::Mat right = read_gray(kPairs + "/kitti06_frame12/right.png");
  const StereoRig rig(PinholeIntrinsics{707.0912, 707.0912, 601.8873, 183.1104},
                      379.8145 / 707.0912);
  StereoExtractor plain(settings_with(2000), rig), shared(settings_with(2000), rig);
  const StereoFeatures expected = plain.extract(left, right);
  int beside_runs = 0;
  StereoFeatures got;
  shared.extract(left, right, got, [&] { ++beside_runs; });
  EXPECT_EQ(beside_runs, 1);
  ASSERT_EQ(got.left.size(), expected.left.size());
  ASSERT_EQ(got.right.size(), expected.right.size());
  EXPECT_EQ(cv::norm(got.left.descriptors, expected.left.descriptors, cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(cv::norm(got.right.descriptors, expected.right.descriptors, cv::NORM_HAMMING), 0.0);
  EXPECT_EQ(got.matches.depth, expected.matches.depth);
  EXPECT_EQ(got.matches.u_right, expected.matches.u_right);
  // An exception in the task reaches the caller.
  EXPECT_THROW(shared.extract(left, right, got, [] { throw std::runtime_error("inference"); }),
               std::runtime_error);
}

// The same right image 15 grey levels brighter: the zero-mean SAD gives exactly the same depths,
// the raw SAD loses or moves many of them. The offset is applied to the right pyramid only, so the
// keypoints and descriptors stay those of the original (the extraction is not the point here).
TEST(StereoMatcher, ZeroMeanSadIgnoresABrightnessOffsetBetweenTheCameras) {
  const cv::Mat left = read_gray(kPairs + "/kitti06_frame12/left.png");
  const cv::Mat right = read_gray(kPairs + "/kitti06_frame12/right.png");
  const StereoRig rig(PinholeIntrinsics{707.0912, 707.0912, 601.8873, 183.1104},
                      379.8145 / 707.0912);
  // The right image's range squeezed into [20, 224] first, so that adding 15 saturates nothing.
  cv::Mat squeezed;
  right.convertTo(squeezed, CV_8U, 0.8, 20.0);
  OrbExtractor l(settings_with(2000)), r(settings_with(2000));
  const OrbFeatures fl = l.extract(left), fr = r.extract(squeezed);
  std::vector<cv::Mat> brighter;
  for (const cv::Mat& level : r.pyramid()) {
    brighter.emplace_back();
    level.convertTo(brighter.back(), CV_8U, 1.0, 15.0);
  }
  StereoMatchOptions options;
  const StereoMatches zero_mean =
      match_stereo(fl, fr, l.pyramid(), r.pyramid(), l.levels(), rig, options);
  const StereoMatches zero_mean_brighter =
      match_stereo(fl, fr, l.pyramid(), brighter, l.levels(), rig, options);
  EXPECT_GT(zero_mean.count(), static_cast<int>(fl.size() / 2));
  EXPECT_EQ(zero_mean.depth, zero_mean_brighter.depth);
  EXPECT_EQ(zero_mean.u_right, zero_mean_brighter.u_right);

  options.zero_mean = false;
  const StereoMatches raw =
      match_stereo(fl, fr, l.pyramid(), r.pyramid(), l.levels(), rig, options);
  const StereoMatches raw_brighter =
      match_stereo(fl, fr, l.pyramid(), brighter, l.levels(), rig, options);
  int same = 0;
  for (std::size_t i = 0; i < fl.size(); ++i)
    if (raw.depth[i] > 0.0f && raw.depth[i] == raw_brighter.depth[i]) ++same;
  EXPECT_LT(same, raw.count() / 2) << same << " of " << raw.count() << " raw-SAD depths unchanged";
}

TEST(StereoMatcher, RejectsMismatchedInput) {
  const StereoRig rig(PinholeIntrinsics{700, 700, 300, 200}, 0.5);
  StereoExtractor stereo(settings_with(500), rig);
  EXPECT_THROW(stereo.extract(cv::Mat(400, 600, CV_8U, cv::Scalar(0)),
                              cv::Mat(300, 600, CV_8U, cv::Scalar(0))),
               Error);
  EXPECT_THROW(
      StereoExtractor(settings_with(500), StereoRig(PinholeIntrinsics{700, 700, 0, 0}, 0.0)),
      Error);
  // Blank images: no features, no matches, no crash.
  const StereoFeatures blank = stereo.extract(cv::Mat(400, 600, CV_8U, cv::Scalar(0)),
                                              cv::Mat(400, 600, CV_8U, cv::Scalar(0)));
  EXPECT_EQ(blank.matches.count(), 0);
}

}  // namespace
}  // namespace sbaslam::feature
