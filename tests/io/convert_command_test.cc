// `sba-slam convert`: trajectory format conversion through the built CLI.

#include <gtest/gtest.h>

#include <cmath>

#include "eval/eval_test_support.h"
#include "sbaslam/eval/kitti_odometry.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::io {
namespace {

using test::quoted;

// Awkward doubles (no short decimal form) so that any precision loss would show.
Trajectory awkward_trajectory() {
  Trajectory traj;
  for (int i = 0; i < 25; ++i) {
    const double a = 0.1 * i + 1.0 / 3.0;
    const SE3 pose(SO3::exp(Vec3(std::sin(a), 0.7 * a, -std::cos(2.0 * a))),
                   Vec3(std::exp(a), -a / 7.0, 1e-9 * a + 1e3));
    traj.push_back(17.0 / 3.0 + 0.05 * i, pose);
  }
  return traj;
}

void expect_same_trajectory(const Trajectory& a, const Trajectory& b, double stamp_tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a.stamps[i], b.stamps[i], stamp_tol) << i;
    EXPECT_LE((a.poses[i].translation() - b.poses[i].translation()).norm(), 1e-12) << i;
    EXPECT_LE((a.poses[i].rotation() - b.poses[i].rotation()).cwiseAbs().maxCoeff(), 1e-14) << i;
  }
}

test::CliRun convert(const std::string& in, const std::string& out, const std::string& options) {
  return test::run_cli("convert " + quoted(in) + " " + quoted(out) + " " + options);
}

TEST(ConvertCommand, TumToKittiAndBackKeepsStampsAndPoses) {
  test::TempDir dir;
  const Trajectory original = awkward_trajectory();
  write_tum_trajectory(dir.file("in.tum"), original);
  const test::CliRun to_kitti =
      convert(dir.file("in.tum"), dir.file("out.kitti"),
              "--from tum --to kitti --save-times " + quoted(dir.file("times.txt")));
  ASSERT_EQ(to_kitti.exit_code, 0) << to_kitti.output;
  EXPECT_EQ(read_kitti_trajectory(dir.file("out.kitti")).size(), original.size());

  const test::CliRun back =
      convert(dir.file("out.kitti"), dir.file("back.tum"),
              "--from kitti --to tum --times " + quoted(dir.file("times.txt")));
  ASSERT_EQ(back.exit_code, 0) << back.output;
  expect_same_trajectory(original, read_tum_trajectory(dir.file("back.tum")), 0.0);
}

TEST(ConvertCommand, TumToEurocAndBackKeepsPosesAndNanosecondStamps) {
  test::TempDir dir;
  const Trajectory original = awkward_trajectory();
  write_tum_trajectory(dir.file("in.tum"), original);
  ASSERT_EQ(convert(dir.file("in.tum"), dir.file("out.csv"), "--from tum --to euroc").exit_code, 0);
  const test::CliRun back =
      convert(dir.file("out.csv"), dir.file("back.tum"), "--from euroc --to tum");
  ASSERT_EQ(back.exit_code, 0) << back.output;
  // EuRoC stores integer nanoseconds.
  expect_same_trajectory(original, read_tum_trajectory(dir.file("back.tum")), 0.6e-9);
}

TEST(ConvertCommand, KittiNeedsOneStampPerRow) {
  test::TempDir dir;
  write_kitti_trajectory(dir.file("in.kitti"), awkward_trajectory());
  const test::CliRun no_times =
      convert(dir.file("in.kitti"), dir.file("out.tum"), "--from kitti --to tum");
  EXPECT_EQ(no_times.exit_code, 1);
  EXPECT_NE(no_times.output.find("--times"), std::string::npos) << no_times.output;

  test::write_text_file(dir.file("times.txt"), "0.0\n0.1\n");
  const test::CliRun mismatch =
      convert(dir.file("in.kitti"), dir.file("out.tum"),
              "--from kitti --to tum --times " + quoted(dir.file("times.txt")));
  EXPECT_EQ(mismatch.exit_code, 1);
  EXPECT_NE(mismatch.output.find("sba-slam: error: " + dir.file("times.txt") +
                                 ": 2 timestamps but " + dir.file("in.kitti") + " holds 25 poses"),
            std::string::npos)
      << mismatch.output;

  test::write_text_file(dir.file("bad_times.txt"), "0.0\nabc\n");
  const test::CliRun bad =
      convert(dir.file("in.kitti"), dir.file("out.tum"),
              "--from kitti --to tum --times " + quoted(dir.file("bad_times.txt")));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find(dir.file("bad_times.txt") + ":2:"), std::string::npos) << bad.output;

  const test::CliRun times_from_tum =
      convert(dir.file("in.kitti"), dir.file("out.kitti"),
              "--from tum --to kitti --times " + quoted(dir.file("times.txt")));
  EXPECT_EQ(times_from_tum.exit_code, 1);
  EXPECT_NE(times_from_tum.output.find("--times applies only"), std::string::npos)
      << times_from_tum.output;
}

TEST(ConvertCommand, Kitti00AsTumGivesTheSameDriftAsPairedRows) {
  // KITTI -> TUM with the sequence's times.txt, then the KITTI metric paired by stamp: the same
  // numbers as row pairing, up to the rotations' projection onto SO(3) (the file's 7-digit
  // rotations are not exactly orthonormal).
  const std::string gt = test::shared_trajectory("KITTI_00_gt.txt");
  const std::string orb = test::shared_trajectory("KITTI_00_ORB.txt");
  const std::string times = test::shared_trajectory("KITTI_00_gt_times.txt");
  test::TempDir dir;
  ASSERT_EQ(
      convert(gt, dir.file("gt.tum"), "--from kitti --to tum --times " + quoted(times)).exit_code,
      0);
  ASSERT_EQ(
      convert(orb, dir.file("orb.tum"), "--from kitti --to tum --times " + quoted(times)).exit_code,
      0);

  eval::TrajectoryPairSettings rows;
  rows.reference_path = gt;
  rows.estimate_path = orb;
  eval::TrajectoryPairSettings stamps = rows;
  stamps.format = TrajectoryFormat::kTum;
  stamps.reference_path = dir.file("gt.tum");
  stamps.estimate_path = dir.file("orb.tum");
  const eval::TrajectoryPair by_rows = eval::load_trajectory_pair(rows);
  const eval::TrajectoryPair by_stamps = eval::load_trajectory_pair(stamps);
  ASSERT_EQ(by_stamps.paired.estimate.size(), 4541u);
  const eval::KittiOdometryResult a =
      eval::kitti_odometry_errors(by_rows.paired.reference, by_rows.paired.estimate, {});
  const eval::KittiOdometryResult b =
      eval::kitti_odometry_errors(by_stamps.paired.reference, by_stamps.paired.estimate, {});
  EXPECT_EQ(a.segments.size(), b.segments.size());
  EXPECT_NEAR(eval::to_percent(a.t_err), eval::to_percent(b.t_err), 1e-3);
  EXPECT_NEAR(eval::to_deg_per_100m(a.r_err), eval::to_deg_per_100m(b.r_err), 1e-3);
}

}  // namespace
}  // namespace sbaslam::io
