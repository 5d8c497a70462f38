#include "sbaslam/eval/evaluator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "eval/eval_test_support.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/io/euroc_sensor.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::eval {
namespace {

const std::string kEurocDir = std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro";
const std::string kBodyTum = kEurocDir + "/groundtruth/body_tum.txt";
const std::string kCam0Yaml = kEurocDir + "/mav0/cam0/sensor.yaml";

std::string error_of(const EvalSettings& settings) {
  try {
    evaluate(settings);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void expect_error_containing(const EvalSettings& settings, const std::string& text) {
  const std::string message = error_of(settings);
  EXPECT_NE(message.find(text), std::string::npos) << "message: '" << message << "'";
}

EvalSettings tum_ape(const std::string& reference, const std::string& estimate) {
  EvalSettings settings;
  settings.format = io::TrajectoryFormat::kTum;
  settings.reference_path = reference;
  settings.estimate_path = estimate;
  return settings;
}

TEST(Evaluate, RefusesFewerThanTwoMatchedPoses) {
  test::TempDir dir;
  test::write_text_file(dir.file("ref.txt"), "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  test::write_text_file(dir.file("est.txt"), "1.001 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n");
  expect_error_containing(tum_ape(dir.file("ref.txt"), dir.file("est.txt")),
                          "only 1 matched pose(s)");
}

TEST(Evaluate, RefusesNoOverlapInTime) {
  test::TempDir dir;
  test::write_text_file(dir.file("est.txt"), "50 0 0 0 0 0 0 1\n51 1 0 0 0 0 0 1\n");
  expect_error_containing(tum_ape(kBodyTum, dir.file("est.txt")), "no overlap in time");
}

TEST(Evaluate, RefusesNanNamingFileAndLine) {
  test::TempDir dir;
  test::write_text_file(dir.file("est.txt"), "0 0 0 0 0 0 0 1\n1 nan 0 0 0 0 0 1\n");
  expect_error_containing(tum_ape(kBodyTum, dir.file("est.txt")), dir.file("est.txt") + ":2:");
}

TEST(Evaluate, RefusesKittiFilesOfDifferentLengths) {
  test::TempDir dir;
  test::write_text_file(dir.file("est.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  EvalSettings settings;
  settings.format = io::TrajectoryFormat::kKitti;
  settings.reference_path = test::shared_trajectory("KITTI_00_gt.txt");
  settings.estimate_path = dir.file("est.txt");
  expect_error_containing(settings, "same length");
}

TEST(Evaluate, RefusesRpeWithoutPairsAndNToAlignWithoutAlignment) {
  EvalSettings settings = tum_ape(kBodyTum, kBodyTum);
  settings.metric = Metric::kRpe;
  settings.rpe = {1000.0, DeltaUnit::kMeters, false};
  expect_error_containing(settings, "no pose pairs");
  settings = tum_ape(kBodyTum, kBodyTum);
  settings.n_to_align = 10;
  expect_error_containing(settings, "without an alignment");
}

TEST(Evaluate, IdenticalTrajectoriesHaveZeroError) {
  EvalSettings settings = tum_ape(kBodyTum, kBodyTum);
  const EvalResult result = evaluate(settings);
  EXPECT_EQ(result.n_matched, 95u);
  EXPECT_EQ(result.stats.max, 0.0);
}

// The estimate is the camera trajectory T_W_B * T_BS: compared with the body ground truth it is
// off by the lever arm |t_BS| at every pose; through --ref-body-to-cam it matches.
// Writes the fixture's body ground truth moved onto cam0 (T_W_B * T_BS) to `path`.
void write_camera_trajectory(const SE3& T_BS, const std::string& path) {
  Trajectory camera = io::read_tum_trajectory(kBodyTum);
  for (SE3& pose : camera.poses) pose = pose * T_BS;
  io::write_tum_trajectory(path, camera);
}

TEST(Evaluate, RefBodyToCamComparesTheCameraTrajectory) {
  test::TempDir dir;
  const SE3 T_BS = io::read_euroc_camera_sensor(kCam0Yaml).T_BS;
  write_camera_trajectory(T_BS, dir.file("cam.txt"));

  EvalSettings settings = tum_ape(kBodyTum, dir.file("cam.txt"));
  const EvalResult body = evaluate(settings);
  EXPECT_NEAR(body.stats.mean, T_BS.translation().norm(), 1e-6);
  settings.ref_body_to_cam_yaml = kCam0Yaml;
  const EvalResult cam = evaluate(settings);
  EXPECT_LT(cam.stats.max, 1e-5);  // the body file holds 6-digit numbers
  settings.relation = PoseRelation::kAngleDeg;
  EXPECT_LT(evaluate(settings).stats.max, 1e-3);
}

// The same through an ORB-SLAM3 settings file whose IMU.T_b_c1 is cam0's T_BS (the way TUM-VI's
// camera-to-IMU calibration reaches a user without sensor.yaml files).
TEST(Evaluate, RefBodyToCamReadsTheSettingsImuToCameraPose) {
  test::TempDir dir;
  const SE3 T_BS = io::read_euroc_camera_sensor(kCam0Yaml).T_BS;
  write_camera_trajectory(T_BS, dir.file("cam.txt"));
  Settings orb_slam3 = load_settings(std::string(SBASLAM_SOURCE_DIR) + "/config/EuRoC_stereo.yaml");
  save_settings(orb_slam3, dir.file("no_imu.yaml"));
  orb_slam3.T_body_cam0 = T_BS;
  save_settings(orb_slam3, dir.file("inertial.yaml"));

  EvalSettings settings = tum_ape(kBodyTum, dir.file("cam.txt"));
  settings.ref_body_to_cam_yaml = kCam0Yaml;
  const EvalResult from_sensor = evaluate(settings);
  settings.ref_body_to_cam_yaml = dir.file("inertial.yaml");
  const EvalResult from_settings = evaluate(settings);
  EXPECT_LT(from_settings.stats.max, 1e-5);
  EXPECT_NEAR(from_settings.stats.rmse, from_sensor.stats.rmse, 1e-12);

  settings.ref_body_to_cam_yaml = dir.file("no_imu.yaml");
  try {
    evaluate(settings);
    ADD_FAILURE() << "no error for settings without IMU.T_b_c1";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(dir.file("no_imu.yaml")), std::string::npos) << message;
    EXPECT_NE(message.find("IMU.T_b_c1"), std::string::npos) << message;
  }
}

TEST(Evaluate, EurocFormatReadsAnAslCsvReferenceAndATumEstimate) {
  test::TempDir dir;
  io::write_euroc_trajectory(dir.file("data.csv"), io::read_tum_trajectory(kBodyTum));
  EvalSettings settings = tum_ape(dir.file("data.csv"), kBodyTum);
  settings.format = io::TrajectoryFormat::kEuroc;
  const EvalResult result = evaluate(settings);
  EXPECT_EQ(result.n_matched, 95u);
  EXPECT_LT(result.stats.max, 1e-12);
}

TEST(EvalCli, RefusesUnknownNamesWithOneLine) {
  const std::string ref = test::quoted(kBodyTum);
  for (const char* bad :
       {"--format tumx", "--format tum --align sim4", "--format tum --pose-relation speed"}) {
    const test::CliRun run = test::run_cli("eval ape " + ref + " " + ref + " " + std::string(bad));
    EXPECT_EQ(run.exit_code, 1) << bad;
    EXPECT_EQ(run.output.rfind("sba-slam: error: ", 0), 0u) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
  const test::CliRun run =
      test::run_cli("eval rpe " + ref + " " + ref + " --format tum --delta 1 --delta-unit km");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("unknown delta unit 'km'"), std::string::npos) << run.output;
}

TEST(EvalCli, SaveErrorsWritesOneLinePerPair) {
  test::TempDir dir;
  const std::string errors = dir.file("errors.txt");
  const test::CliRun run = test::run_cli(
      "eval rpe " + test::quoted(test::shared_trajectory("KITTI_00_gt.txt")) + " " +
      test::quoted(test::shared_trajectory("KITTI_00_ORB.txt")) +
      " --format kitti --delta 100 --delta-unit m --save-errors " + test::quoted(errors));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::istringstream lines(test::read_text_file(errors));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "# first_index second_index trans_part");
  int count = 0;
  double first = 0.0, second = 0.0, error = 0.0, max_error = 0.0;
  while (lines >> first >> second >> error) {
    EXPECT_LT(first, second);
    max_error = std::max(max_error, error);
    ++count;
  }
  EXPECT_EQ(count, 35);
  EXPECT_NEAR(max_error, 2.292953393069983, 1e-9);  // evo's max for this case
}

// APE's errors file carries the matched reference positions and the aligned estimate's, whose
// distances are the trans_part errors (evo's rmse for this case: 1.3034497145650565).
TEST(EvalCli, ApeSaveErrorsCarriesTheReferenceAndAlignedEstimatePositions) {
  test::TempDir dir;
  const std::string errors = dir.file("errors.txt");
  const std::string ref = test::shared_trajectory("KITTI_00_gt.txt");
  const std::string est = test::shared_trajectory("KITTI_00_ORB.txt");
  const test::CliRun run =
      test::run_cli("eval ape " + test::quoted(ref) + " " + test::quoted(est) +
                    " --format kitti --align se3 --save-errors " + test::quoted(errors));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const io::PoseMatrixSeries truth = io::read_pose_matrices(ref, io::TrajectoryFormat::kKitti);
  const io::PoseMatrixSeries raw = io::read_pose_matrices(est, io::TrajectoryFormat::kKitti);
  std::istringstream lines(test::read_text_file(errors));
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "# index trans_part ref_x ref_y ref_z est_x est_y est_z");
  std::size_t count = 0;
  double index = 0.0, error = 0.0, sse = 0.0, moved = 0.0;
  Vec3 r, e;
  while (lines >> index >> error >> r.x() >> r.y() >> r.z() >> e.x() >> e.y() >> e.z()) {
    ASSERT_EQ(index, static_cast<double>(count));
    EXPECT_NEAR((r - e).norm(), error, 1e-9);
    EXPECT_NEAR((r - truth.poses[count].topRightCorner<3, 1>()).norm(), 0.0, 1e-9);
    moved = std::max(moved, (e - raw.poses[count].topRightCorner<3, 1>()).norm());
    sse += error * error;
    ++count;
  }
  EXPECT_EQ(count, 4541u);
  EXPECT_NEAR(std::sqrt(sse / static_cast<double>(count)), 1.3034497145650565, 1e-9);
  EXPECT_GT(moved, 1.0);  // the estimate is written as aligned, not as read
}

}  // namespace
}  // namespace sbaslam::eval
