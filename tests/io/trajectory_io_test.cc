#include "sbaslam/io/trajectory_io.h"

#include <gtest/gtest.h>

#include "eval/eval_test_support.h"
#include "sbaslam/core/error.h"

namespace sbaslam::io {
namespace {

// Poses with awkward doubles (no short decimal form) so that precision loss would show.
Trajectory awkward_trajectory() {
  Trajectory traj;
  for (int i = 0; i < 20; ++i) {
    const double a = 0.1 * i + 1.0 / 3.0;
    const SE3 pose(SO3::exp(Vec3(std::sin(a), 0.7 * a, -std::cos(2.0 * a))),
                   Vec3(std::exp(a), -a / 7.0, 1e-9 * a + 1e5));
    traj.push_back(1403715273.262142976 + 0.05 * i, pose);
  }
  return traj;
}

void expect_same_poses(const Trajectory& a, const Trajectory& b, double rotation_tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.poses[i].translation(), b.poses[i].translation()) << i;
    EXPECT_LE((a.poses[i].rotation() - b.poses[i].rotation()).cwiseAbs().maxCoeff(), rotation_tol)
        << i;
  }
}

std::string error_reading(const std::string& path, TrajectoryFormat format) {
  try {
    read_trajectory(path, format);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryIo, TumRoundTripIsExact) {
  test::TempDir dir;
  const Trajectory traj = awkward_trajectory();
  write_tum_trajectory(dir.file("t.txt"), traj);
  const Trajectory back = read_tum_trajectory(dir.file("t.txt"));
  EXPECT_EQ(back.stamps, traj.stamps);
  // Quaternions are written exactly; re-normalising a unit quaternion may move the last bit.
  expect_same_poses(back, traj, 1e-15);
  write_tum_trajectory(dir.file("t2.txt"), back);
  const Trajectory again = read_tum_trajectory(dir.file("t2.txt"));
  expect_same_poses(again, back, 1e-15);
}

TEST(TrajectoryIo, KittiRoundTripKeepsMatricesAndNumbersRows) {
  test::TempDir dir;
  const Trajectory traj = awkward_trajectory();
  write_kitti_trajectory(dir.file("k.txt"), traj);
  const Trajectory back = read_kitti_trajectory(dir.file("k.txt"));
  expect_same_poses(back, traj, 1e-15);
  for (std::size_t i = 0; i < back.size(); ++i) EXPECT_EQ(back.stamps[i], static_cast<double>(i));
  // The raw reader gives back exactly the written matrices.
  const PoseMatrixSeries raw = read_pose_matrices(dir.file("k.txt"), TrajectoryFormat::kKitti);
  for (std::size_t i = 0; i < raw.size(); ++i)
    EXPECT_EQ(Mat34(raw.poses[i].topRows<3>()), traj.poses[i].matrix3x4()) << i;
}

TEST(TrajectoryIo, EurocRoundTripKeepsNanosecondStamps) {
  test::TempDir dir;
  const Trajectory traj = awkward_trajectory();
  write_euroc_trajectory(dir.file("e.csv"), traj);
  const std::string text = test::read_text_file(dir.file("e.csv"));
  EXPECT_EQ(text.rfind("#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w []", 0), 0u);
  const Trajectory back = read_euroc_groundtruth(dir.file("e.csv"));
  expect_same_poses(back, traj, 1e-15);
  for (std::size_t i = 0; i < back.size(); ++i)
    EXPECT_NEAR(back.stamps[i], traj.stamps[i], 1e-6);  // seconds near 1.4e9 hold ~0.2 us
  write_euroc_trajectory(dir.file("e2.csv"), back);
  EXPECT_EQ(test::read_text_file(dir.file("e2.csv")), text);
}

TEST(TrajectoryIo, ReadsTheSharedFixtures) {
  const Trajectory fr1 =
      read_tum_trajectory(test::shared_trajectory("freiburg1_xyz-groundtruth.txt"));
  EXPECT_EQ(fr1.size(), 3000u);
  const Trajectory kitti = read_kitti_trajectory(test::shared_trajectory("KITTI_00_gt.txt"));
  EXPECT_EQ(kitti.size(), 4541u);
  // Raw KITTI values are kept as written (7 digits, not re-orthonormalised).
  const PoseMatrixSeries raw =
      read_pose_matrices(test::shared_trajectory("KITTI_00_gt.txt"), TrajectoryFormat::kKitti);
  EXPECT_EQ(raw.poses[1](0, 0), 9.999978e-01);
  EXPECT_EQ(raw.poses[1](2, 3), 8.586941e-01);
}

TEST(TrajectoryIo, AcceptsEurocGroundTruthWithExtraColumnsAndSpaces) {
  test::TempDir dir;
  test::write_text_file(
      dir.file("gt.csv"),
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
      "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1]\r\n"
      "1403715273262142976, 0.878612, 2.142470, 0.947262, 0.060514, -0.828459, "
      "-0.058956, -0.553641, 0.009474\r\n");
  const Trajectory traj = read_euroc_groundtruth(dir.file("gt.csv"));
  ASSERT_EQ(traj.size(), 1u);
  EXPECT_NEAR(traj.stamps[0], 1403715273.262142976, 1e-6);
  EXPECT_EQ(traj.poses[0].translation(), Vec3(0.878612, 2.142470, 0.947262));
  EXPECT_NEAR(traj.poses[0].quaternion().w(), 0.060514, 1e-5);
}

struct BadInput {
  const char* name;
  TrajectoryFormat format;
  const char* text;
  const char* message;  // expected after "<path>"
};

std::string bad_input_name(const ::testing::TestParamInfo<BadInput>& param) {
  return param.param.name;
}

class TrajectoryIoBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(TrajectoryIoBadInput, FailsWithFileLineAndProblem) {
  test::TempDir dir;
  const std::string path = dir.file("bad.txt");
  test::write_text_file(path, GetParam().text);
  const std::string message = error_reading(path, GetParam().format);
  EXPECT_EQ(message.rfind(path, 0), 0u) << message;
  EXPECT_NE(message.find(GetParam().message), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TrajectoryIoBadInput,
    ::testing::Values(
        BadInput{"Empty", TrajectoryFormat::kTum, "", ": no poses"},
        BadInput{"OnlyComments", TrajectoryFormat::kTum, "# t x y z\n\n", ": no poses"},
        BadInput{"TumColumns", TrajectoryFormat::kTum, "# c\n0 1 2 3 0 0 0\n",
                 ":2: 7 columns, expected 8"},
        BadInput{"TumNotANumber", TrajectoryFormat::kTum, "0 1 2 x3 0 0 0 1\n",
                 ":1: 'x3' is not a number"},
        BadInput{"TumNan", TrajectoryFormat::kTum, "0 0 0 0 0 0 0 1\n1 nan 0 0 0 0 0 1\n",
                 ":2: 'nan' is not a finite number"},
        BadInput{"TumInf", TrajectoryFormat::kTum, "0 0 0 0 0 0 0 -inf\n", ":1: '-inf' is not"},
        BadInput{"TumOverflow", TrajectoryFormat::kTum, "0 1e999 0 0 0 0 0 1\n",
                 ":1: '1e999' is not a finite number"},
        BadInput{"TumZeroQuaternion", TrajectoryFormat::kTum, "0 1 2 3 0 0 0 0\n",
                 ":1: quaternion has norm 0"},
        BadInput{"KittiColumns", TrajectoryFormat::kKitti, "1 0 0 0 0 1 0 0 0 0 1\n",
                 ":1: 11 columns, expected 12"},
        BadInput{"KittiNotRotation", TrajectoryFormat::kKitti, "1 0 0 0 0 1 0 0 0 0 2 0\n",
                 ":1: the 3x3 part is not a rotation"},
        BadInput{"EurocFractionalStamp", TrajectoryFormat::kEuroc, "1.5,0,0,0,1,0,0,0\n",
                 ":1: timestamp '1.5' is not an integer number of nanoseconds"},
        BadInput{"EurocColumns", TrajectoryFormat::kEuroc, "#h\n10,0,0,0,1,0,0\n",
                 ":2: 7 columns, expected 8 or more"}),
    bad_input_name);

TEST(TrajectoryIo, MissingFileAndUnknownFormat) {
  EXPECT_THROW(read_tum_trajectory("/nonexistent/traj.txt"), Error);
  try {
    read_kitti_trajectory("/nonexistent/traj.txt");
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/traj.txt: file not found");
  }
  EXPECT_EQ(parse_trajectory_format("euroc"), TrajectoryFormat::kEuroc);
  EXPECT_THROW(parse_trajectory_format("TUM "), Error);
  EXPECT_THROW(write_tum_trajectory("/nonexistent/dir/t.txt", awkward_trajectory()), Error);
}

}  // namespace
}  // namespace sbaslam::io
