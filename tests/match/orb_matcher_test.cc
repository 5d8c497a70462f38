#include "sbaslam/match/orb_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "helper/images.h"
#include "sbaslam/core/camera.h"
#include "sbaslam/core/lie.h"
#include "sbaslam/feature/keypoint_undistortion.h"
#include "sbaslam/match/hamming.h"

namespace sbaslam::match {
namespace {

const std::string kData = std::string(SBASLAM_SHARED_DIR) + "/data";
const std::string kEuroc = kData + "/euroc_v101_micro";

using test::read_gray;

OrbSettings settings_with(int n_features) {
  return test::orb_settings_with(n_features);
}

TEST(RotationConsistency, KeepsTheThreeMainBins) {
  RotationConsistency rotation(30);
  int id = 0;
  for (int i = 0; i < 50; ++i) rotation.add(id++, 100.0f, 95.0f);   // 5 deg: bin 0
  for (int i = 0; i < 20; ++i) rotation.add(id++, 100.0f, 110.0f);  // -10 = 350 deg: bin 29
  for (int i = 0; i < 10; ++i) rotation.add(id++, 100.0f, 85.0f);   // 15 deg: bin 1
  for (int i = 0; i < 4; ++i) rotation.add(id++, 0.0f, 180.0f);     // 180 deg: outliers
  const std::vector<int> rejected = rotation.inconsistent();
  EXPECT_EQ(rejected, (std::vector<int>{80, 81, 82, 83}));
}

TEST(RotationConsistency, MinorBinsBelowATenthAreRejected) {
  RotationConsistency rotation(30);
  int id = 0;
  for (int i = 0; i < 100; ++i) rotation.add(id++, 10.0f, 10.0f);
  for (int i = 0; i < 5; ++i) rotation.add(id++, 100.0f, 10.0f);  // 5 < 10: rejected
  EXPECT_EQ(rotation.inconsistent().size(), 5u);
}

TEST(BruteForce, DescriptorRowsAreTheNamedRowsInTheirOrder) {
  cv::Mat descriptors(4, 32, CV_8U);
  for (int r = 0; r < 4; ++r) descriptors.row(r).setTo(10 * r + 1);
  const cv::Mat rows = descriptor_rows(descriptors, {3, 0, 3});
  ASSERT_EQ(rows.rows, 3);
  EXPECT_EQ(rows.at<std::uint8_t>(0, 5), 31);
  EXPECT_EQ(rows.at<std::uint8_t>(1, 31), 1);
  EXPECT_EQ(rows.at<std::uint8_t>(2, 0), 31);
  EXPECT_EQ(descriptor_rows(descriptors, {}).rows, 0);
}

TEST(BruteForce, BestDistancesAgreeWithOpenCvAndCrossCheckIsMutual) {
  feature::OrbExtractor extractor(settings_with(500));
  const auto a = extractor.extract(read_gray(kEuroc + "/mav0/cam0/data/1403715273262142976.png"));
  const auto b = extractor.extract(read_gray(kEuroc + "/mav0/cam1/data/1403715273262142976.png"));
  BruteForceOptions options;
  options.max_distance = 256;
  options.cross_check = false;
  const auto matches = match_brute_force(a.descriptors, b.descriptors, options);
  ASSERT_EQ(matches.size(), a.size());
  std::vector<cv::DMatch> reference;
  cv::BFMatcher(cv::NORM_HAMMING).match(a.descriptors, b.descriptors, reference);
  for (std::size_t i = 0; i < matches.size(); ++i)
    EXPECT_EQ(matches[i].distance, static_cast<int>(reference[i].distance));

  options.cross_check = true;
  const auto mutual = match_brute_force(a.descriptors, b.descriptors, options);
  EXPECT_LT(mutual.size(), matches.size());
  const auto backward = match_brute_force(b.descriptors, a.descriptors, options);
  for (const Match& m : mutual) {
    const auto it = std::find_if(backward.begin(), backward.end(),
                                 [&](const Match& x) { return x.query == m.train; });
    ASSERT_NE(it, backward.end());
    EXPECT_EQ(it->train, m.query);
  }
}

// Ground-truth body poses of the EuRoC clip, by timestamp in nanoseconds (TUM format, seconds).
SE3 euroc_body_pose(double stamp_s) {
  std::ifstream in(kEuroc + "/groundtruth/body_tum.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t, x, y, z, qx, qy, qz, qw;
    s >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    if (std::abs(t - stamp_s) < 1e-3) return SE3(Quat(qw, qx, qy, qz), Vec3(x, y, z));
  }
  ADD_FAILURE() << "no ground truth at " << stamp_s;
  return SE3();
}

struct EurocPair {
  std::vector<feature::OrbKeypoint> first, second;  // undistorted
  feature::OrbFeatures first_raw, second_raw;
  Mat3 H;  // infinite homography taking first undistorted pixels to the second
  double translation = 0.0;
};

EurocPair consecutive_euroc_frames() {
  const PinholeCamera camera(
      PinholeIntrinsics{458.654, 457.296, 367.215, 248.375},
      RadTanDistortion{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0});
  const Mat4 T_BS_m =
      (Mat4() << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
       0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768, -0.0257744366974,
       0.00375618835797, 0.999660727178, 0.00981073058949, 0.0, 0.0, 0.0, 1.0)
          .finished();
  const SE3 T_BS = SE3::from_matrix(T_BS_m);
  const std::string names[2] = {"1403715273262142976", "1403715273312143104"};
  feature::OrbExtractor extractor(settings_with(1200));
  EurocPair pair;
  pair.first_raw = extractor.extract(read_gray(kEuroc + "/mav0/cam0/data/" + names[0] + ".png"));
  pair.second_raw = extractor.extract(read_gray(kEuroc + "/mav0/cam0/data/" + names[1] + ".png"));
  pair.first = feature::undistort_keypoints(pair.first_raw.keypoints, camera);
  pair.second = feature::undistort_keypoints(pair.second_raw.keypoints, camera);
  const SE3 T_w_c0 = euroc_body_pose(1403715273.262143) * T_BS;
  const SE3 T_w_c1 = euroc_body_pose(1403715273.312143) * T_BS;
  const SE3 T_c1_c0 = T_w_c1.inverse() * T_w_c0;
  Mat3 K;
  K << 458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1;
  pair.H = K * T_c1_c0.rotation() * K.inverse();
  pair.translation = T_c1_c0.translation().norm();
  return pair;
}

// A match is consistent with the ground truth when the first keypoint, moved by the rotation's
// infinite homography, lands within 2 px of the second. With the tiny GT translation (checked
// below 2 mm) the parallax of any point farther than 1 m is under fx * 0.002 / 1 = 0.9 px, so a
// correct match passes and a wrong one (a different corner) almost never does.
double inlier_fraction(const EurocPair& pair, const std::vector<Match>& matches) {
  int inliers = 0;
  for (const Match& m : matches) {
    const Vec3 p = pair.H * Vec3(pair.first[m.query].x, pair.first[m.query].y, 1.0);
    const double dx = p.x() / p.z() - pair.second[m.train].x;
    const double dy = p.y() / p.z() - pair.second[m.train].y;
    if (std::hypot(dx, dy) < 2.0) ++inliers;
  }
  return matches.empty() ? 0.0 : static_cast<double>(inliers) / matches.size();
}

TEST(OrbMatcher, ConsecutiveEurocFramesMatchUnderGroundTruth) {
  const EurocPair pair = consecutive_euroc_frames();
  ASSERT_LT(pair.translation, 0.002);

  BruteForceOptions brute;
  brute.nn_ratio = 0.8f;
  const auto bf = match_brute_force(pair.first_raw.descriptors, pair.second_raw.descriptors, brute);
  EXPECT_GT(bf.size(), 300u);
  EXPECT_GE(inlier_fraction(pair, bf), 0.8) << bf.size() << " brute-force matches";

  const FeatureGrid grid(pair.second, cv::Rect2f(-40, -40, 832, 560));
  const feature::ScaleLevels levels = feature::ScaleLevels::make(8, 1.2);
  const FrameView view{pair.second, pair.second_raw.descriptors, grid, levels};
  WindowOptions window;
  window.window = 30.0f;
  window.level0_only = false;
  const auto windowed = match_in_window(pair.first, pair.first_raw.descriptors, view, window);
  EXPECT_GT(windowed.size(), 300u);
  EXPECT_GE(inlier_fraction(pair, windowed), 0.8) << windowed.size() << " window matches";
}

TEST(OrbMatcher, ProjectionFindsShiftedKeypoints) {
  const cv::Mat image = read_gray(kData + "/stereo_pairs/kitti06_frame12/left.png");
  const float sx = 6.0f, sy = 3.0f;
  cv::Mat shifted;
  const cv::Matx23d shift(1, 0, sx, 0, 1, sy);
  cv::warpAffine(image, shifted, shift, image.size());
  feature::OrbExtractor extractor(settings_with(2000));
  const auto a = extractor.extract(image);
  const auto b = extractor.extract(shifted);
  const FeatureGrid grid(b.keypoints, cv::Rect2f(0, 0, static_cast<float>(image.cols),
                                                 static_cast<float>(image.rows)));
  const FrameView view{b.keypoints, b.descriptors, grid, extractor.levels()};

  std::vector<ProjectedPoint> points(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& kp = a.keypoints[i];
    // A rough prediction, 2 px off, as a motion model would give.
    points[i] = {kp.x + sx + 2.0f,
                 kp.y + sy - 1.0f,
                 -1.0f,
                 kp.octave,
                 a.descriptors.ptr<std::uint8_t>(static_cast<int>(i)),
                 kp.angle,
                 1.0f};
  }
  ProjectionOptions options;
  options.radius = 4.0f;
  options.levels_above = 1;
  options.check_orientation = true;
  const auto matches = match_by_projection(points, view, options);
  int correct = 0;
  std::vector<int> used(b.size(), 0);
  for (const Match& m : matches) {
    const auto& p = a.keypoints[m.query];
    const auto& q = b.keypoints[m.train];
    // The same corner, allowing for its position's quantisation at the coarser octave.
    const float scale = extractor.levels().scale[std::max(p.octave, q.octave)];
    if (std::hypot(p.x + sx - q.x, p.y + sy - q.y) <= 2.0f * scale) ++correct;
    EXPECT_EQ(used[m.train]++, 0) << "keypoint matched twice";
    EXPECT_LE(m.distance, kThresholdHigh);
  }
  EXPECT_GT(matches.size(), a.size() / 2);
  EXPECT_GE(correct, 0.95 * matches.size()) << correct << " of " << matches.size();

  // Keypoints already taken are not matched again.
  std::vector<char> taken(b.size(), 1);
  EXPECT_TRUE(match_by_projection(points, view, options, &taken).empty());
}

}  // namespace
}  // namespace sbaslam::match
