#pragma once
// Rendered sequences for tests, and a deterministic `run` of one the simulator wrote into DIR/data
// (KITTI layout, sequence 00), with its outputs in DIR/out.

#include <string>

#include "helper/temp_dir.h"
#include "sbaslam/runner.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam::test {

// Writes `frames` frames of a scene (its dataset layout) from `first_frame` on into DIR/data;
// returns the scene, e.g. to render more of its frames in memory.
inline sim::Scene render_scene(const TempDir& dir, const std::string& name, int frames,
                               int first_frame = 0) {
  sim::SceneOptions options;
  options.name = name;
  options.first_frame = first_frame;
  sim::Scene scene = sim::make_scene(options);
  sim::WriteOptions write;
  write.frames = frames;
  sim::write_dataset(scene, dir.file("data"), write);
  return scene;
}

inline sim::Scene render_city_loop(const TempDir& dir, int frames, int first_frame = 0) {
  return render_scene(dir, "city-loop", frames, first_frame);
}

inline RunConfig rendered_kitti_run(const TempDir& dir) {
  RunConfig config;
  config.settings_path = dir.file("data/settings.yaml");
  config.dataset_kind = "kitti";
  config.dataset_path = dir.file("data/sequences/00");
  config.out_dir = dir.file("out");
  config.deterministic = true;
  config.progress = false;
  return config;
}

}  // namespace sbaslam::test
