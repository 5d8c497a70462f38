#pragma once
// Whole-file reads for the project's own inputs (trajectories, map files), so that a missing or
// unreadable file is an Error naming it, never an empty string read as an empty input.

#include <string>

namespace sbaslam {

// The bytes of PATH. `what` names it in the missing-file message ("{path}: {what} not found").
std::string read_input_file(const std::string& path, const std::string& what = "file");

}  // namespace sbaslam
