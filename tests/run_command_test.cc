// `sba-slam run` as a user or a job scheduler stops it: a SIGTERM in the middle of a real-time
// run still leaves the trajectory and run.json, and the exit code says which signal ended it.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "helper/cli.h"
#include "helper/temp_dir.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam {
namespace {

TEST(RunCommand, TerminatedRealtimeRunWritesItsOutputsAndExitsWith143) {
  test::TempDir dir;
  const std::string out = dir.file("run");
  // EuRoC is 20 Hz: fed in real time, the 95 frames take 4.7 s, so the signal lands mid-run.
  const pid_t pid = test::spawn_cli(
      {"run", "--settings", std::string(SBASLAM_SOURCE_DIR) + "/config/EuRoC_stereo.yaml",
       "--dataset", "euroc", "--path", std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro",
       "--out", out, "--realtime"},
      dir.file("log.txt"));
  ASSERT_GT(pid, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  ASSERT_EQ(kill(pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string log = test::read_text_file(dir.file("log.txt"));
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << log;
  EXPECT_NE(log.find("SIGTERM: stopping after"), std::string::npos) << log;

  const nlohmann::json run = nlohmann::json::parse(test::read_text_file(out + "/run.json"));
  EXPECT_EQ(run.at("stopped_by"), "SIGTERM");
  const std::size_t frames = run.at("frames");
  EXPECT_LT(frames, 95u);
  const Trajectory trajectory = io::read_tum_trajectory(out + "/trajectory.tum");
  EXPECT_EQ(trajectory.size(), run.at("frames_tracked").get<std::size_t>());
  EXPECT_TRUE(std::filesystem::exists(out + "/timing.json"));
}

}  // namespace
}  // namespace sbaslam
