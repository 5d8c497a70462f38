// Rendering speed of the synthetic scenes at their native resolution, on one core.
//   Render<Scene>         one stereo pair with all image effects (items/s = stereo pairs per
//   second) RenderNoEffects<Scene> the two rasterised views only (render_view twice, no image
//   effects) Expose<Effect>        the image effects alone on one 752x480 room view, applied to
//   both views
//                         of a pair (items/s = stereo pairs per second)
// Scene construction (texture generation) is outside the timing.
//   build/bench/sim_render_bench --benchmark_filter=Render --benchmark_min_time=3

#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>

#include "sbaslam/sim/image_effects.h"
#include "sbaslam/sim/renderer.h"
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

int frame_count(const sbaslam::sim::Scene& scene) {
  return scene.max_frames > 0 ? scene.max_frames : scene.default_frames;
}

void label_with_size(benchmark::State& state, const sbaslam::sim::Scene& scene) {
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height));
}

void render_scene(benchmark::State& state, const std::string& name) {
  const sbaslam::sim::Scene& scene = cached_scene(name);
  int index = 0;
  for (auto _ : state) {
    auto frame = sbaslam::sim::render_frame(scene, index);
    benchmark::DoNotOptimize(frame.left.data);
    index = (index + 7) % frame_count(scene);  // spread over the sequence
  }
  label_with_size(state, scene);
}

// The rasteriser alone: the same frames as render_scene, without exposure and effects.
void render_views(benchmark::State& state, const std::string& name) {
  const sbaslam::sim::Scene& scene = cached_scene(name);
  sbaslam::sim::ViewLayers left, right;
  int index = 0;
  for (auto _ : state) {
    const double t = scene.time_of(index);
    sbaslam::sim::render_view(scene.world, scene.camera, scene.left_camera_pose(t), t, left);
    sbaslam::sim::render_view(scene.world, scene.camera, scene.right_camera_pose(t), t, right);
    benchmark::DoNotOptimize(left.radiance.data);
    benchmark::DoNotOptimize(right.radiance.data);
    index = (index + 7) % frame_count(scene);
  }
  label_with_size(state, scene);
}

enum class Effect { kNone, kNoise, kBlur, kVignetting, kAll };

// One effect at a time on a rendered room view, with a 4 px motion blur (a fast turn of the MAV).
void expose(benchmark::State& state, Effect effect) {
  const sbaslam::sim::Scene& scene = cached_scene("room");
  sbaslam::sim::ViewLayers view;
  const double t = scene.time_of(100);
  sbaslam::sim::render_view(scene.world, scene.camera, scene.left_camera_pose(t), t, view);
  sbaslam::sim::ImageEffects fx;
  fx.sensor_noise = effect == Effect::kNoise || effect == Effect::kAll;
  fx.motion_blur = effect == Effect::kBlur || effect == Effect::kAll;
  fx.vignetting = effect == Effect::kVignetting || effect == Effect::kAll;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    for (int view_index = 0; view_index < 2; ++view_index) {
      cv::Mat image =
          sbaslam::sim::expose_image(view.radiance, 1.0, cv::Vec2d(3.8, 1.2), fx, ++seed);
      benchmark::DoNotOptimize(image.data);
    }
  }
  label_with_size(state, scene);
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
BENCHMARK_CAPTURE(render_views, RenderNoEffectsCityLoop, std::string("city-loop"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_views, RenderNoEffectsCityDynamic, std::string("city-dynamic"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_views, RenderNoEffectsRoom, std::string("room"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(render_views, RenderNoEffectsStraight, std::string("straight"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(expose, ExposeNone, Effect::kNone)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(expose, ExposeNoise, Effect::kNoise)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(expose, ExposeBlur, Effect::kBlur)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(expose, ExposeVignetting, Effect::kVignetting)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(expose, ExposeAll, Effect::kAll)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BuildScene, BuildCity, std::string("city-loop"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BuildScene, BuildRoom, std::string("room"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_MAIN();
