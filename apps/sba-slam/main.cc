// sba-slam: one CLI with subcommands. Every user-facing failure becomes a one-line message on
// stderr and a non-zero exit code.

#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.h"
#include "sbaslam/core/error.h"

int main(int argc, char** argv) {
  spdlog::cfg::load_env_levels();  // SPDLOG_LEVEL=debug shows per-keyframe details
  CLI::App app{"sba-slam: feature-based visual SLAM with Salient Bundle Adjustment"};
  app.set_version_flag("--version", std::string("sba-slam ") + SBASLAM_VERSION);
  app.require_subcommand(1);
  sbaslam::cli::add_eval_command(app);
  sbaslam::cli::add_convert_command(app);
  sbaslam::cli::add_simulate_command(app);
  sbaslam::cli::add_run_command(app);
  sbaslam::cli::add_demo_command(app);
  sbaslam::cli::add_bench_features_command(app);
  sbaslam::cli::add_saliency_command(app);
  sbaslam::cli::add_vocabulary_command(app);

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
