// sba-slam convert: trajectory format conversion (as evo_traj ... --save_as_tum/kitti/euroc).
// KITTI files carry no stamps, so KITTI -> TUM/EuRoC takes them from a KITTI times.txt; the other
// way the stamps can be kept in a times.txt of their own. Numbers keep full precision.

#include <fmt/format.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/io/text_lines.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::cli {
namespace {

struct ConvertArguments {
  std::string input;
  std::string output;
  std::string from;
  std::string to;
  std::string times_path;
  std::string save_times_path;
};

// A KITTI times.txt: one stamp in seconds per line.
std::vector<double> read_kitti_times(const std::string& path) {
  std::vector<double> stamps;
  for (const io::TextLine& line : io::read_data_lines(path)) {
    const std::vector<std::string> fields = io::split_fields(line.text, " \t");
    if (fields.size() != 1)
      fail("{}:{}: expected one timestamp, got {} fields", path, line.number, fields.size());
    stamps.push_back(io::parse_number(fields[0], path, line.number, "timestamp"));
  }
  return stamps;
}

void write_kitti_times(const std::string& path, const std::vector<double>& stamps) {
  std::ofstream out = open_output_file(path);
  for (double stamp : stamps) out << fmt::format("{}\n", stamp);  // shortest exact text
  close_output_file(out, path);
}

void check_options(const ConvertArguments& args, io::TrajectoryFormat from,
                   io::TrajectoryFormat to) {
  const bool from_kitti = from == io::TrajectoryFormat::kKitti;
  const bool to_kitti = to == io::TrajectoryFormat::kKitti;
  if (from_kitti && !to_kitti && args.times_path.empty())
    fail("{}: KITTI poses have no stamps; give the sequence's times.txt with --times to write {}",
         args.input, io::trajectory_format_name(to));
  if (!args.times_path.empty() && !(from_kitti && !to_kitti))
    fail("--times applies only to --from kitti with --to tum or euroc (the stamps of a {} file {})",
         io::trajectory_format_name(from), from_kitti ? "are not written to KITTI" : "are its own");
  if (!args.save_times_path.empty() && !(to_kitti && !from_kitti))
    fail("--save-times applies only to --to kitti from tum or euroc");
}

void run_convert(const ConvertArguments& args) {
  const io::TrajectoryFormat from = io::parse_trajectory_format(args.from);
  const io::TrajectoryFormat to = io::parse_trajectory_format(args.to);
  check_options(args, from, to);
  Trajectory trajectory = io::read_trajectory(args.input, from);
  if (!args.times_path.empty()) {
    std::vector<double> stamps = read_kitti_times(args.times_path);
    if (stamps.size() != trajectory.size())
      fail("{}: {} timestamps but {} holds {} poses (one stamp per KITTI row is needed)",
           args.times_path, stamps.size(), args.input, trajectory.size());
    trajectory.stamps = std::move(stamps);
  }
  io::write_trajectory(args.output, trajectory, to);
  if (!args.save_times_path.empty()) write_kitti_times(args.save_times_path, trajectory.stamps);
  std::cout << fmt::format("{}: {} poses, {} -> {}: {}\n", args.input, trajectory.size(),
                           io::trajectory_format_name(from), io::trajectory_format_name(to),
                           args.output);
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto args = std::make_shared<ConvertArguments>();
  CLI::App* convert = app.add_subcommand(
      "convert", "convert a trajectory between the KITTI, TUM and EuRoC formats");
  convert->add_option("IN", args->input, "input trajectory")->required();
  convert->add_option("OUT", args->output, "output trajectory")->required();
  convert->add_option("--from", args->from, "kitti | tum | euroc")->required();
  convert->add_option("--to", args->to, "kitti | tum | euroc")->required();
  convert->add_option("--times", args->times_path,
                      "KITTI times.txt (one stamp in seconds per row): stamps for --from kitti");
  convert->add_option("--save-times", args->save_times_path,
                      "with --to kitti: also write the stamps as a KITTI times.txt");
  convert->callback([args] { run_convert(*args); });
}

}  // namespace sbaslam::cli
