#include "sbaslam/eval/kitti_odometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "eval/eval_test_support.h"
#include "sbaslam/core/error.h"

namespace sbaslam::eval {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Mat4 pose(const Mat3& R, const Vec3& t) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = t;
  return T;
}

Mat3 yaw(double angle) {
  return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
}

// n + 1 poses along x, `spacing` metres apart, stamped 0.1 s apart.
PoseSeries straight_drive(std::size_t n, double spacing) {
  PoseSeries series;
  for (std::size_t i = 0; i <= n; ++i) {
    series.stamps.push_back(0.1 * static_cast<double>(i));
    series.poses.push_back(pose(Mat3::Identity(), Vec3(spacing * static_cast<double>(i), 0, 0)));
  }
  return series;
}

std::string error_of(const PoseSeries& reference, const PoseSeries& estimate,
                     const KittiOdometrySettings& settings) {
  try {
    kitti_odometry_errors(reference, estimate, settings);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(KittiSegments, PathDistancesAccumulateStepLengths) {
  const std::vector<Mat4> poses = {
      pose(Mat3::Identity(), Vec3(0, 0, 0)), pose(Mat3::Identity(), Vec3(3, 4, 0)),
      pose(yaw(1.0), Vec3(3, 4, 0)), pose(Mat3::Identity(), Vec3(3, 4, 2))};
  const std::vector<double> dist = path_distances(poses);
  ASSERT_EQ(dist.size(), 4u);
  EXPECT_DOUBLE_EQ(dist[0], 0.0);
  EXPECT_DOUBLE_EQ(dist[1], 5.0);
  EXPECT_DOUBLE_EQ(dist[2], 5.0);  // rotating in place adds no path
  EXPECT_DOUBLE_EQ(dist[3], 7.0);
}

TEST(KittiSegments, EndIsFirstFrameStrictlyBeyondTheLength) {
  const std::vector<double> dist = {0, 1, 2, 2, 5, 6};
  EXPECT_EQ(segment_end(dist, 0, 2.0), std::optional<std::size_t>(4));  // 2 is not > 2
  EXPECT_EQ(segment_end(dist, 1, 1.0), std::optional<std::size_t>(4));
  EXPECT_EQ(segment_end(dist, 0, 1.5), std::optional<std::size_t>(2));
  EXPECT_EQ(segment_end(dist, 4, 0.5), std::optional<std::size_t>(5));
  EXPECT_FALSE(segment_end(dist, 0, 6.0));  // the path ends at exactly 6
  EXPECT_FALSE(segment_end(dist, 6, 1.0));  // start beyond the end
}

TEST(KittiOdometry, StartsEveryStepFramesAndSkipsSegmentsPastTheEnd) {
  PoseSeries toy;
  for (double x : {0.0, 1.0, 2.0, 2.0, 5.0, 6.0}) {
    toy.stamps.push_back(x);
    toy.poses.push_back(pose(Mat3::Identity(), Vec3(x, 0, 0)));
  }
  KittiOdometrySettings settings;
  settings.lengths = {2.0, 4.0};
  settings.step = 2;
  const KittiOdometryResult result = kitti_odometry_errors(toy, toy, settings);
  // Starts 0, 2, 4. From 0: L=2 ends at 4 (dist 5), L=4 ends at 4; from 2: L=2 ends at 4
  // (5 > 4), L=4 needs > 6; from 4: nothing.
  ASSERT_EQ(result.segments.size(), 3u);
  EXPECT_EQ(result.segments[0].first, 0u);
  EXPECT_EQ(result.segments[0].last, 4u);
  EXPECT_EQ(result.segments[0].length, 2.0);
  EXPECT_EQ(result.segments[1].first, 0u);
  EXPECT_EQ(result.segments[1].length, 4.0);
  EXPECT_EQ(result.segments[2].first, 2u);
  EXPECT_EQ(result.segments[2].last, 4u);
  ASSERT_EQ(result.per_length.size(), 2u);
  EXPECT_EQ(result.per_length[0].segments, 2u);
  EXPECT_EQ(result.per_length[1].segments, 1u);
  EXPECT_LT(result.t_err, 1e-12);
  EXPECT_LT(result.r_err, 1e-12);
  EXPECT_DOUBLE_EQ(result.reference_path_length, 6.0);
}

TEST(KittiOdometry, OnePercentScaleErrorOnAStraightKilometre) {
  const PoseSeries reference = straight_drive(1000, 1.0);
  const PoseSeries estimate = straight_drive(1000, 1.01);
  const KittiOdometryResult result = kitti_odometry_errors(reference, estimate, {});
  // The devkit closes a segment at the first frame strictly beyond L: here L + 1 metres, so the
  // translation error over L is 1% of L + 1.
  double expected_sum = 0.0;
  std::size_t expected_count = 0;
  ASSERT_EQ(result.per_length.size(), 8u);
  for (const KittiLengthSummary& summary : result.per_length) {
    const double L = summary.length;
    // Starts 0, 10, ... with i + L + 1 <= 1000.
    const std::size_t count = static_cast<std::size_t>((999.0 - L) / 10.0) + 1;
    EXPECT_EQ(summary.segments, count) << "L = " << L;
    EXPECT_NEAR(summary.t_err, 0.01 * (L + 1.0) / L, 1e-12) << "L = " << L;
    EXPECT_EQ(summary.r_err, 0.0);
    expected_sum += static_cast<double>(count) * 0.01 * (L + 1.0) / L;
    expected_count += count;
  }
  EXPECT_EQ(result.per_length.front().segments, 90u);
  EXPECT_EQ(result.per_length.back().segments, 20u);
  EXPECT_EQ(result.segments.size(), expected_count);
  EXPECT_NEAR(result.t_err, expected_sum / static_cast<double>(expected_count), 1e-12);
  EXPECT_NEAR(to_percent(result.per_length.front().t_err), 1.01, 1e-10);
}

TEST(KittiOdometry, ConstantYawRateErrorGivesKnownRotationDrift) {
  // The estimate drives 1 m per frame along its own heading, which turns 0.01 deg every metre:
  // 1 deg per 100 m.
  const double yaw_per_metre = 0.01 * kDegToRad;
  const PoseSeries reference = straight_drive(1000, 1.0);
  PoseSeries estimate;
  Mat4 current = Mat4::Identity();
  for (std::size_t i = 0; i <= 1000; ++i) {
    estimate.stamps.push_back(reference.stamps[i]);
    estimate.poses.push_back(current);
    current = current * pose(yaw(yaw_per_metre), Vec3(1, 0, 0));
  }
  KittiOdometrySettings settings;
  settings.lengths = {100.0};
  const KittiOdometryResult result = kitti_odometry_errors(reference, estimate, settings);
  // Each segment spans 101 frames: 1.01 deg over 100 m.
  EXPECT_NEAR(to_deg_per_100m(result.r_err), 1.01, 1e-6);
  EXPECT_NEAR(to_deg_per_m(result.r_err), 0.0101, 1e-8);
  for (const KittiSegmentError& segment : result.segments)
    EXPECT_NEAR(segment.r_err, 101.0 * yaw_per_metre / 100.0, 1e-9);
  EXPECT_GT(result.t_err, 0.0);  // the bent path also misplaces the end point
}

TEST(KittiOdometry, UnitConversions) {
  EXPECT_DOUBLE_EQ(to_percent(0.0123), 1.23);
  EXPECT_DOUBLE_EQ(to_deg_per_m(kDegToRad), 1.0);
  EXPECT_NEAR(to_deg_per_100m(0.25 * kDegToRad / 100.0), 0.25, 1e-15);
}

TEST(KittiOdometry, RefusesInvalidSettingsAndShortPaths) {
  const PoseSeries reference = straight_drive(50, 1.0);
  KittiOdometrySettings settings;
  EXPECT_NE(error_of(reference, reference, settings).find("no segment fits"), std::string::npos);
  EXPECT_NE(error_of(reference, reference, settings).find("50 m long"), std::string::npos);
  settings.lengths = {};
  EXPECT_NE(error_of(reference, reference, settings).find("no segment lengths"), std::string::npos);
  settings.lengths = {10.0, -5.0};
  EXPECT_NE(error_of(reference, reference, settings).find("-5"), std::string::npos);
  settings.lengths = {10.0};
  settings.step = 0;
  EXPECT_NE(error_of(reference, reference, settings).find("step"), std::string::npos);
  settings.step = 10;
  EXPECT_NE(error_of(reference, straight_drive(40, 1.0), settings).find("paired poses"),
            std::string::npos);
}

TEST(KittiOdometry, TumEstimateWithLostFramesIsPairedByStampAndSim3Aligned) {
  // A bent 600 m path (Umeyama needs more than a line), estimate at half scale, rotated and
  // shifted, with every third frame lost.
  PoseSeries reference;
  Mat4 current = Mat4::Identity();
  for (std::size_t i = 0; i <= 600; ++i) {
    reference.stamps.push_back(0.1 * static_cast<double>(i));
    reference.poses.push_back(current);
    current = current * pose(yaw(0.3 * kDegToRad), Vec3(1, 0, 0));
  }
  const Mat4 world_change = pose(yaw(0.7), Vec3(5, -3, 2));
  PoseSeries estimate;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (i % 3 == 2) continue;
    Mat4 T = reference.poses[i];
    T.topRightCorner<3, 1>() *= 0.5;
    estimate.stamps.push_back(reference.stamps[i] + 0.002);
    estimate.poses.push_back(world_change * T);
  }
  TrajectoryPairSettings input;
  input.format = io::TrajectoryFormat::kTum;
  KittiOdometrySettings settings;
  settings.lengths = {100.0, 200.0};

  const TrajectoryPair raw = pair_trajectories(reference, estimate, input);
  EXPECT_EQ(raw.paired.estimate.size(), 401u);
  const KittiOdometryResult unaligned =
      kitti_odometry_errors(raw.paired.reference, raw.paired.estimate, settings);
  EXPECT_GT(to_percent(unaligned.t_err), 40.0);  // half scale: about 50 % of every segment
  EXPECT_LT(unaligned.r_err, 1e-9);              // a world change leaves relative rotations

  input.align = AlignmentMode::kSim3;
  const TrajectoryPair aligned = pair_trajectories(reference, estimate, input);
  EXPECT_NEAR(aligned.alignment.scale, 2.0, 1e-9);
  const KittiOdometryResult result =
      kitti_odometry_errors(aligned.paired.reference, aligned.paired.estimate, settings);
  EXPECT_LT(result.t_err, 1e-9);
  EXPECT_LT(result.r_err, 1e-7);
}

// ---- CLI on the real KITTI 00 fixture
// ------------------------------------------------------------

nlohmann::json read_json(const std::string& path) {
  return nlohmann::json::parse(test::read_text_file(path));
}

TEST(KittiOdometryCli, Kitti00OrbSlam2MatchesTheLibraryAndSingleLengthMode) {
  const std::string gt = test::shared_trajectory("KITTI_00_gt.txt");
  const std::string orb = test::shared_trajectory("KITTI_00_ORB.txt");
  test::TempDir dir;
  const test::CliRun all =
      test::run_cli("eval kitti " + test::quoted(gt) + " " + test::quoted(orb) +
                    " --format kitti --json " + test::quoted(dir.file("all.json")));
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_NE(all.output.find("r_rel (deg/100m)"), std::string::npos) << all.output;
  const nlohmann::json json = read_json(dir.file("all.json"));
  ASSERT_EQ(json["per_length"].size(), 8u);

  const PoseSeries reference = io::read_pose_matrices(gt, io::TrajectoryFormat::kKitti);
  const PoseSeries estimate = io::read_pose_matrices(orb, io::TrajectoryFormat::kKitti);
  const KittiOdometryResult library = kitti_odometry_errors(reference, estimate, {});
  EXPECT_EQ(json["segments"].get<std::size_t>(), library.segments.size());
  EXPECT_DOUBLE_EQ(json["t_rel_percent"].get<double>(), to_percent(library.t_err));
  EXPECT_DOUBLE_EQ(json["r_rel_deg_per_100m"].get<double>(), to_deg_per_100m(library.r_err));
  // The published ORB-SLAM2 stereo result on KITTI 00 (Mur-Artal & Tardos 2017, table I), to the
  // two digits it is printed with.
  EXPECT_NEAR(json["t_rel_percent"].get<double>(), 0.70, 0.005);
  EXPECT_NEAR(json["r_rel_deg_per_100m"].get<double>(), 0.25, 0.005);

  const test::CliRun single = test::run_cli("eval kitti " + test::quoted(gt) + " " +
                                            test::quoted(orb) + " --format kitti --lengths 100" +
                                            " --json " + test::quoted(dir.file("100.json")));
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const nlohmann::json only_100 = read_json(dir.file("100.json"));
  EXPECT_EQ(only_100["segments"], json["per_length"][0]["segments"]);
  EXPECT_DOUBLE_EQ(only_100["t_rel_percent"].get<double>(),
                   json["per_length"][0]["t_rel_percent"].get<double>());
}

TEST(KittiOdometryCli, RefusesBadLengthsAndStep) {
  const std::string gt = test::quoted(test::shared_trajectory("KITTI_00_gt.txt"));
  const test::CliRun bad_length =
      test::run_cli("eval kitti " + gt + " " + gt + " --format kitti --lengths 100,abc");
  EXPECT_EQ(bad_length.exit_code, 1);
  EXPECT_NE(bad_length.output.find("sba-slam: error: --lengths: 'abc' is not a number"),
            std::string::npos)
      << bad_length.output;
  const test::CliRun bad_step =
      test::run_cli("eval kitti " + gt + " " + gt + " --format kitti --step 0");
  EXPECT_EQ(bad_step.exit_code, 1);
  EXPECT_NE(bad_step.output.find("--step must be at least 1"), std::string::npos)
      << bad_step.output;
}

}  // namespace
}  // namespace sbaslam::eval
