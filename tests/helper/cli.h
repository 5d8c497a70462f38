#pragma once
// Runs the sba-slam program of this build, as a user would from a shell.

#include <cstdlib>
#include <fstream>
#include <string>

namespace sbaslam::test {

// `sba-slam ARGUMENTS > OUTPUT 2>&1`; returns the exit code.
inline int run_cli(const std::string& arguments, const std::string& output) {
  const std::string command = std::string(SBASLAM_CLI) + " " + arguments + " > " + output + " 2>&1";
  return WEXITSTATUS(std::system(command.c_str()));
}

// The first line of a text file (an error message is one line).
inline std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace sbaslam::test
