// The README's quick start, `sba-slam demo`: it renders its own city drive, runs stereo SLAM on it
// and evaluates it, with no data besides the project's.

#include "sbaslam/demo.h"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>

#include "helper/cli.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/stop_signal.h"

namespace sbaslam {
namespace {

TEST(Demo, ShortDemoTracksEveryFrameAndRemovesItsTemporaryFolder) {
  DemoConfig config;
  config.frames = 30;
  const DemoResult r = run_demo(config);
  EXPECT_EQ(r.frames, 30u);
  EXPECT_EQ(r.frames_tracked, 30u);
  EXPECT_GT(r.keyframes, 2u);
  EXPECT_GT(r.path_length_m, 25.0);  // about 1 m per frame
  EXPECT_LT(r.ate_rmse_m, 0.1);
  EXPECT_LT(r.rpe_rmse_m, 0.05);
  EXPECT_GT(r.tracking_median_ms, 0.0);
  EXPECT_FALSE(std::filesystem::exists(r.work_dir)) << r.work_dir;
}

TEST(Demo, ASignalStopsItWithoutEvaluatingAndRemovesTheTemporaryFolder) {
  // The run's own guard shares this one's flag, so the run sees a Ctrl-C from before it began.
  const StopSignalGuard ctrl_c;
  std::raise(SIGINT);
  DemoConfig config;
  config.frames = 10;
  const DemoResult r = run_demo(config);
  EXPECT_EQ(r.stop_signal, SIGINT);
  EXPECT_EQ(r.frames_tracked, 0u);
  EXPECT_EQ(r.ate_rmse_m, 0.0);
  EXPECT_FALSE(std::filesystem::exists(r.work_dir)) << r.work_dir;
}

TEST(Demo, CommandPrintsItsFiguresAndKeepsTheRunInTheWorkFolder) {
  test::TempDir dir;
  ASSERT_EQ(test::run_cli("demo --frames 20 --work-dir " + dir.file("demo"), dir.file("out.txt")),
            0);
  const std::string printed = test::read_text_file(dir.file("out.txt"));
  EXPECT_NE(printed.find("tracked frames       20/20"), std::string::npos) << printed;
  EXPECT_NE(printed.find("ATE (SE3-aligned)"), std::string::npos) << printed;
  EXPECT_TRUE(std::filesystem::exists(dir.file("demo/run/trajectory.tum")));
}

TEST(Demo, TooFewFramesIsAOneLineError) {
  test::TempDir dir;
  EXPECT_NE(test::run_cli("demo --frames 5", dir.file("out.txt")), 0);
  EXPECT_NE(test::first_line(dir.file("out.txt")).find("--frames: the demo needs at least 10"),
            std::string::npos)
      << test::first_line(dir.file("out.txt"));
}

}  // namespace
}  // namespace sbaslam
