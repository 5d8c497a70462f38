#pragma once
// Each subcommand lives in its own file and registers itself on the root app here.

#include <CLI/CLI.hpp>

namespace sbaslam::cli {


}  // namespace sbaslam::cli
