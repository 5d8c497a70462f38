#include "sbaslam/eval/scale_drift.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "eval/eval_test_support.h"
#include "sbaslam/core/error.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::eval {
namespace {

constexpr double kTurnPerStep = 2.0 * M_PI / 1500.0;  // a polygon of 1 m sides, radius ~239 m
constexpr std::size_t kScaleChange = 505;             // where the 5th 100 m segment ends

Mat4 step_motion(double step_length) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(kTurnPerStep, Vec3::UnitZ()).toRotationMatrix();
  T(0, 3) = step_length;
  return T;
}

// 1001 poses on a planar polygon: 1 m per step for the reference; the estimate makes the same
// turns with steps of 1 m up to pose 505 and 1.5 m after (a sudden 50 % scale change).
PoseSeries polygon_drive(bool with_scale_change) {
  PoseSeries series;
  Mat4 current = Mat4::Identity();
  for (std::size_t i = 0; i <= 1000; ++i) {
    series.stamps.push_back(0.1 * static_cast<double>(i));
    series.poses.push_back(current);
    current = current * step_motion(with_scale_change && i >= kScaleChange ? 1.5 : 1.0);
  }
  return series;
}

std::string error_of(const PoseSeries& reference, double length) {
  try {
    scale_drift_series(reference, reference, length);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ScaleDrift, ConsecutiveSegmentsChainAndDropTheShortRest) {
  const std::vector<double> dist = {0, 1, 2, 3, 4, 5, 6, 7};
  const auto segments = consecutive_segments(dist, 2.0);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0], std::make_pair(std::size_t{0}, std::size_t{3}));
  EXPECT_EQ(segments[1], std::make_pair(std::size_t{3}, std::size_t{6}));
  EXPECT_TRUE(consecutive_segments(dist, 7.0).empty());
}

TEST(ScaleDrift, RatiosAndErrorsAreThoseConstructed) {
  const PoseSeries reference = polygon_drive(false);
  const PoseSeries estimate = polygon_drive(true);
  const ScaleDriftResult result = scale_drift(reference, estimate, 100.0);
  // Segments of 101 steps: 0-101, 101-202, ..., 808-909; 909 + 101 is past the end.
  const std::vector<ScaleDriftSegment>& raw = result.unaligned.segments;
  ASSERT_EQ(raw.size(), 9u);
  // The chord of n polygon sides of length 1 with turn a: sin(n a / 2) / sin(a / 2).
  const double chord_101 = std::sin(101.0 * kTurnPerStep / 2.0) / std::sin(kTurnPerStep / 2.0);
  for (std::size_t k = 0; k < raw.size(); ++k) {
    const bool scaled = raw[k].first >= kScaleChange;
    EXPECT_EQ(raw[k].first, 101 * k);
    EXPECT_EQ(raw[k].last, 101 * (k + 1));
    EXPECT_NEAR(raw[k].start_distance, 101.0 * static_cast<double>(k), 1e-9);
    EXPECT_NEAR(raw[k].reference_length, 101.0, 1e-9);
    EXPECT_NEAR(raw[k].scale_ratio, scaled ? 1.5 : 1.0, 1e-12) << "segment " << k;
    // Same turns, 1.5 times the chord: the end is misplaced by half the chord.
    EXPECT_NEAR(raw[k].t_err, scaled ? 0.5 * chord_101 / 100.0 : 0.0, 1e-9) << "segment " << k;
    EXPECT_LT(raw[k].r_err, 1e-9);
  }
  const ScaleDriftSummary& s = result.unaligned.summary;
  EXPECT_EQ(s.segments, 9u);
  EXPECT_NEAR(s.ratio_min, 1.0, 1e-12);
  EXPECT_NEAR(s.ratio_max, 1.5, 1e-12);
  EXPECT_NEAR(s.ratio_mean, (5.0 * 1.0 + 4.0 * 1.5) / 9.0, 1e-12);
  EXPECT_NEAR(s.ratio_spread, 1.5, 1e-12);
  EXPECT_NEAR(s.t_err_mean, 4.0 * 0.5 * chord_101 / 100.0 / 9.0, 1e-9);

  // A global Sim3 scales every ratio by the same factor: the drift (max / min) stays.
  ASSERT_EQ(result.sim3_aligned.segments.size(), 9u);
  EXPECT_LT(result.sim3.scale, 1.0);
  EXPECT_GT(result.sim3.scale, 1.0 / 1.5);
  for (std::size_t k = 0; k < raw.size(); ++k)
    EXPECT_NEAR(result.sim3_aligned.segments[k].scale_ratio, result.sim3.scale * raw[k].scale_ratio,
                1e-9);
  EXPECT_NEAR(result.sim3_aligned.summary.ratio_spread, 1.5, 1e-9);
  EXPECT_NEAR(result.reference_path_length, 1000.0, 1e-9);
}

TEST(ScaleDrift, RefusesBadLengthsShortPathsAndUnpairedSeries) {
  const PoseSeries reference = polygon_drive(false);
  EXPECT_NE(error_of(reference, 0.0).find("not a positive number"), std::string::npos);
  EXPECT_NE(error_of(reference, 2000.0).find("no full 2000 m segment"), std::string::npos);
  PoseSeries shorter = reference;
  shorter.poses.pop_back();
  shorter.stamps.pop_back();
  EXPECT_THROW(scale_drift_series(reference, shorter, 100.0), Error);
}

Trajectory to_trajectory(const PoseSeries& series) {
  Trajectory trajectory;
  for (std::size_t i = 0; i < series.size(); ++i)
    trajectory.push_back(series.stamps[i], SE3::from_matrix(series.poses[i]));
  return trajectory;
}

TEST(ScaleDriftCli, WritesPerSegmentJson) {
  test::TempDir dir;
  io::write_kitti_trajectory(dir.file("gt.txt"), to_trajectory(polygon_drive(false)));
  io::write_kitti_trajectory(dir.file("est.txt"), to_trajectory(polygon_drive(true)));
  const test::CliRun run =
      test::run_cli("eval scale-drift " + test::quoted(dir.file("gt.txt")) + " " +
                    test::quoted(dir.file("est.txt")) + " --format kitti --segment 100 --json " +
                    test::quoted(dir.file("drift.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("sim3-aligned:"), std::string::npos) << run.output;
  const nlohmann::json json = nlohmann::json::parse(test::read_text_file(dir.file("drift.json")));
  EXPECT_EQ(json["segment_length"].get<double>(), 100.0);
  ASSERT_EQ(json["unaligned"]["segments"].size(), 9u);
  EXPECT_NEAR(json["unaligned"]["summary"]["ratio_max"].get<double>(), 1.5, 1e-9);
  EXPECT_NEAR(json["unaligned"]["segments"][8]["scale_ratio"].get<double>(), 1.5, 1e-9);
  EXPECT_NEAR(json["sim3_aligned"]["summary"]["ratio_spread"].get<double>(), 1.5, 1e-9);
}

}  // namespace
}  // namespace sbaslam::eval
