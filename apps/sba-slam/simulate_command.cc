// sba-slam simulate: renders a synthetic scene (stereo images, depth, semantic labels, exact poses)
// in the layout of the real dataset it imitates.

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

#include "commands.h"
#include "sbaslam/core/error.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam::cli {
namespace {

struct SimulateArguments {
  std::string scene;
  int frames = 0;
  int first_frame = 0;
  bool frames_given = false;
  long long seed = 1;
  std::string out;
  int dynamic_objects = 12;
  bool velodyne = false;
  bool fisheye = false;
  bool no_noise = false, no_blur = false, no_exposure = false, no_vignetting = false;
  int threads = 0;
  double resolution_scale = 1.0;
  std::string texture_dir;
};

// A one-line progress bar redrawn in place; only on a terminal.
class ProgressBar {
 public:
  ProgressBar() : enabled_(isatty(fileno(stderr)) != 0), start_(std::chrono::steady_clock::now()) {}
  void update(int done, int total) {
    if (!enabled_) return;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const int width = 40;
    const int filled = total > 0 ? width * done / total : width;
    std::fprintf(stderr, "\r[%s%s] %d/%d frames, %.1f frames/s ", std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), done, total,
                 seconds > 0 ? done / seconds : 0.0);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
};

void run_simulate(const SimulateArguments& args) {
  if (args.frames_given && args.frames <= 0)
    fail("--frames: must be positive, got {}", args.frames);
  if (args.seed < 0) fail("--seed: must be non-negative, got {}", args.seed);
  if (args.dynamic_objects < 0)
    fail("--dynamic-objects: must be non-negative, got {}", args.dynamic_objects);
  if (args.threads < 0) fail("--threads: must be non-negative, got {}", args.threads);
  sim::SceneOptions options;
  options.name = args.scene;
  options.seed = static_cast<std::uint64_t>(args.seed);
  options.dynamic_objects = args.dynamic_objects;
  options.resolution_scale = args.resolution_scale;
  options.texture_dir = args.texture_dir;
  options.first_frame = args.first_frame;
  options.fisheye = args.fisheye;
  options.effects.sensor_noise = !args.no_noise;
  options.effects.motion_blur = !args.no_blur;
  options.effects.exposure_changes = !args.no_exposure;
  options.effects.vignetting = !args.no_vignetting;
  const sim::Scene scene = sim::make_scene(options);

  sim::WriteOptions write;
  write.frames = args.frames_given ? args.frames : 0;
  write.velodyne = args.velodyne;
  write.threads =
      args.threads > 0
          ? args.threads
          : std::max(1, std::min(2, static_cast<int>(std::thread::hardware_concurrency())));
  ProgressBar bar;
  write.progress = [&bar](int done, int total) { bar.update(done, total); };
  const auto start = std::chrono::steady_clock::now();
  const int frames = sim::write_dataset(scene, args.out, write);
  bar.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{}: {} frames of '{}' (seed {}) written to {} in {:.1f} s ({:.1f} frames/s)\n",
             scene.layout == sim::DatasetLayout::kKitti ? "kitti" : "euroc", frames, args.scene,
             args.seed, args.out, seconds, frames / std::max(seconds, 1e-9));
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto args = std::make_shared<SimulateArguments>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "render a synthetic stereo sequence (images, depth, Cityscapes labels, exact poses) in the "
      "KITTI (city scenes) or EuRoC (room) layout");
  cmd->add_option("--scene", args->scene, "city-loop, city-dynamic, room or straight")->required();
  CLI::Option* frames =
      cmd->add_option("--frames", args->frames, "number of frames (default: the whole scene)");
  cmd->add_option(
         "--first-frame", args->first_frame,
         "start the output at this frame of the scene's motion (a segment of a long scene)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the world, the motion and the noise")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_option("--dynamic-objects", args->dynamic_objects,
                  "moving cars and pedestrians (city-dynamic)")
      ->capture_default_str();
  cmd->add_flag("--no-noise", args->no_noise, "no sensor noise");
  cmd->add_flag("--no-blur", args->no_blur, "no motion blur");
  cmd->add_flag("--velodyne", args->velodyne,
                "KITTI-layout scenes: also write velodyne/NNNNNN.bin scans (~0.4 MB a frame)");
  cmd->add_flag("--fisheye", args->fisheye,
                "room: a Kannala-Brandt fisheye stereo rig (sensor.yaml \"equidistant\", "
                "settings.yaml \"KannalaBrandt8\")");
  cmd->add_flag("--no-exposure-changes", args->no_exposure, "constant camera gain");
  cmd->add_flag("--no-vignetting", args->no_vignetting, "no vignetting");
  cmd->add_option("--threads", args->threads, "render threads (default: up to 2)");
  cmd->add_option("--resolution-scale", args->resolution_scale,
                  "scale of the images and intrinsics (e.g. 0.5 for a quick look)")
      ->capture_default_str();
  cmd->add_option("--texture-dir", args->texture_dir,
                  "folder of photographs to use as facade (city) or wall (room) textures");
  cmd->callback([args, frames] {
    args->frames_given = frames->count() > 0;
    run_simulate(*args);
  });
}

}  // namespace sbaslam::cli
