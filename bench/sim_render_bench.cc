// Rendering speed of the synthetic scenes at their native resolution, on one core: one iteration
// renders one stereo pair with all image effects (items/s = stereo pairs per second). Scene
// construction (texture generation) is outside the timing.
//   build/sim_render_bench --benchmark_filter=Render

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "sbaslam/sim/scene.h"

namespace {

const sbaslam::sim::Scene& cached_scene(const std::string& name) {
  static std::map<std::string, std::unique_ptr<sbaslam::sim::Scene>> scenes;
  auto& s = scenes[name];
  if (!s) {
    sbaslam::sim::SceneOptions options;
    options.name = name;
    options.seed = 1;
    s = std::make_unique<sbaslam::sim::Scene>(sbaslam::sim::make_scene(options));
  }
  return *s;
}

void render_scene(benchmark::State& state, const std::string& name) {
  const sbaslam::sim::Scene& scene = cached_scene(name);
  const int frames = scene.max_frames > 0 ? scene.max_frames : scene.default_frames;
  int index = 0;
  for (auto _ : state) {
    auto frame = sbaslam::sim::render_frame(scene, index);
    benchmark::DoNotOptimize(frame.left.data);
    index = (index + 7) % frames;  // spread over the sequence
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height));
}

void BuildScene(benchmark::State& state, const std::string& name) {
  for (auto _ : state) {
    sbaslam::sim::SceneOptions options;
    options.name = name;
    auto scene = sbaslam::sim::make_scene(options);
    benchmark::DoNotOptimize(scene.world.quads.data());
  }
}

}  // namespace

BENCHMARK_CAPTURE(render_scene, RenderCityLoop, std::string("city-loop"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_scene, RenderCityDynamic, std::string("city-dynamic"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_scene, RenderRoom, std::string("room"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_scene, RenderStraight, std::string("straight"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BuildScene, BuildCity, std::string("city-loop"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BuildScene, BuildRoom, std::string("room"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_MAIN();
