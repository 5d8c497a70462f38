// sba-slam: one CLI with subcommands. Every user-facing failure becomes a one-line message on
// stderr and a non-zero exit code.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.h"
#include "sbaslam/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"sba-slam: feature-based visual SLAM with Salient Bundle Adjustment"};
  app.set_version_flag("--version", std::string("sba-slam ") + SBASLAM_VERSION);
  app.require_subcommand(1);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const sbaslam::Error& e) {
    std::cerr << "sba-slam: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sba-slam: internal error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
