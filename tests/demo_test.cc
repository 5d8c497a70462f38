// The README's quick start, `sba-slam demo`: it renders its own city drive, runs stereo SLAM on it
// and evaluates it, with no data besides the project's.

#include "sbaslam/demo.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

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

TEST(Demo, ASignalWhileRenderingStopsItBeforeSlamAndRemovesTheTemporaryFolder) {
  // The demo's guard shares this one's flag, so it sees a Ctrl-C from before it began.
  const StopSignalGuard ctrl_c;
  std::raise(SIGINT);
  DemoConfig config;
  config.frames = 10;
  const DemoResult r = run_demo(config);
  EXPECT_EQ(r.stop_signal, SIGINT);
  EXPECT_EQ(r.frames_rendered, 0u);
  EXPECT_EQ(r.frames, 0u);
  EXPECT_FALSE(std::filesystem::exists(r.work_dir)) << r.work_dir;
}

TEST(Demo, ASignalDuringTheSlamRunStopsItWithoutEvaluating) {
  test::TempDir dir;
  const std::string work_dir = dir.file("demo");
  const StopSignalGuard ctrl_c;
  // Ctrl-C once the SLAM run has made its output folder, i.e. after all frames were rendered.
  std::thread user([&work_dir] {
    // Bounded, so that a demo failing before its run cannot leave the test waiting forever.
    for (int wait = 0; wait < 120000 && !std::filesystem::exists(work_dir + "/run"); ++wait)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::raise(SIGINT);
  });
  DemoConfig config;
  config.frames = 10;
  config.work_dir = work_dir;
  const DemoResult r = run_demo(config);
  user.join();
  EXPECT_EQ(r.stop_signal, SIGINT);
  EXPECT_EQ(r.frames_rendered, 10u);
  EXPECT_EQ(r.frames, 0u);  // set only when the run is evaluated
  EXPECT_TRUE(std::filesystem::exists(work_dir + "/run/trajectory.tum"));
}

TEST(Demo, CommandTerminatedWhileRenderingExitsWith143AndRemovesItsTemporaryFolder) {
  test::TempDir dir;
  const std::string log_path = dir.file("log.txt");
  const pid_t pid = test::spawn_cli({"demo"}, log_path);  // 200 frames: rendering takes seconds
  ASSERT_GT(pid, 0);
  // The log names the temporary folder once rendering has begun.
  const std::string marker = " into ", suffix = "/city-loop";
  std::string log;
  for (int wait = 0; wait < 3000 && log.find(suffix) == std::string::npos; ++wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    log = test::read_text_file(log_path);
  }
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  log = test::read_text_file(log_path);
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << log;
  EXPECT_NE(log.find("stopped by SIGTERM; nothing evaluated"), std::string::npos) << log;
  const std::size_t begin = log.find(marker), end = log.find(suffix);
  ASSERT_NE(begin, std::string::npos) << log;
  ASSERT_NE(end, std::string::npos) << log;
  const std::string work_dir = log.substr(begin + marker.size(), end - begin - marker.size());
  EXPECT_FALSE(std::filesystem::exists(work_dir)) << work_dir;
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
