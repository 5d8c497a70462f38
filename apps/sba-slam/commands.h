#pragma once
// Each subcommand lives in its own file and registers itself on the root app here.

#include <CLI/CLI.hpp>

namespace sbaslam::cli {

void add_eval_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_bench_features_command(CLI::App& app);
void add_saliency_command(CLI::App& app);
void add_vocabulary_command(CLI::App& app);

}  // namespace sbaslam::cli
