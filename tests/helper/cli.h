#pragma once
// Runs the sba-slam program of this build, as a user would from a shell.

#include <fcntl.h>
#include <spawn.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace sbaslam::test {

// `sba-slam ARGUMENTS > OUTPUT 2>&1`; returns the exit code.
inline int run_cli(const std::string& arguments, const std::string& output) {
  const std::string command = std::string(SBASLAM_CLI) + " " + arguments + " > " + output + " 2>&1";
  return WEXITSTATUS(std::system(command.c_str()));
}

// Starts `sba-slam ARGUMENTS` in the background with its output in `log`; returns its process id.
inline pid_t spawn_cli(const std::vector<std::string>& arguments, const std::string& log) {
  std::vector<std::string> words = {SBASLAM_CLI};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// The first line of a text file (an error message is one line).
inline std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace sbaslam::test
