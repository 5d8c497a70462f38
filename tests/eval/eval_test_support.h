#pragma once
// Helpers for the trajectory and evaluation tests: fixture paths and running the built CLI.
// Temp dirs and text files come from helper/temp_dir.h.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include "helper/temp_dir.h"

namespace sbaslam::test {

inline std::string shared_trajectory(const std::string& name) {
  return std::string(SBASLAM_SHARED_DIR) + "/data/trajectories/" + name;
}

inline std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

struct CliRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs the sba-slam CLI with the given (already quoted) arguments.
inline CliRun run_cli(const std::string& arguments) {
  const std::string command = quoted(SBASLAM_CLI) + " " + arguments + " 2>&1";
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

}  // namespace sbaslam::test
