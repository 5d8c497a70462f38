// The three BAs on problems shaped like a KITTI-style forward drive: keyframes 1 m apart along
// the optical axis, points on the walls of a street and far ahead. The local BA window has the
// size our city-loop runs see (21 free keyframes, the older ones fixed, ~4000 points with ~8
// observations each); motion-only BA has one frame's ~900 matches.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>

#include "sbaslam/mapping/local_mapper.h"
#include "sbaslam/optimize/bundle_adjuster.h"
#include "sbaslam/optimize/pose_optimizer.h"

namespace {

using sbaslam::SE3;
using sbaslam::SO3;
using sbaslam::Vec3;
using sbaslam::Vec6;
using namespace sbaslam::optimize;

constexpr double kWidth = 1241.0, kHeight = 376.0;

RectifiedCamera kitti_camera() {
  RectifiedCamera cam;
  cam.fx = cam.fy = 718.856;
  cam.cx = 607.19;
  cam.cy = 185.22;
  cam.bf = 0.54 * cam.fx;
  return cam;
}

// Camera k at z = k metres, looking down +z; T_cw maps world to camera.
SE3 pose_of_keyframe(int k) {
  return SE3(SO3(), Vec3(0.0, 0.0, -static_cast<double>(k)));
}

// A point on a street wall (x = +-8 m), on the road (y = 1.7 m) or far ahead.
Vec3 street_point(std::mt19937& rng, double z_max) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double kind = unit(rng);
  const double z = z_max * unit(rng);
  if (kind < 0.6) return {unit(rng) < 0.5 ? -8.0 : 8.0, -6.0 + 7.5 * unit(rng), z};
  if (kind < 0.85) return {-6.0 + 12.0 * unit(rng), 1.7, z};
  return {-30.0 + 60.0 * unit(rng), -15.0 + 15.0 * unit(rng), z_max + 60.0 * unit(rng)};
}

bool project(const RectifiedCamera& cam, const SE3& T_cw, const Vec3& p_w, bool stereo,
             std::mt19937& rng, PixelObservation& obs) {
  const Vec3 p = T_cw * p_w;
  if (p.z() < 1.0 || p.z() > 80.0) return false;
  std::normal_distribution<double> noise(0.0, 1.0);
  obs.u = cam.fx * p.x() / p.z() + cam.cx + noise(rng);
  obs.v = cam.fy * p.y() / p.z() + cam.cy + noise(rng);
  if (obs.u < 0.0 || obs.u >= kWidth || obs.v < 0.0 || obs.v >= kHeight) return false;
  obs.u_right = stereo && p.z() < 40.0 ? obs.u - cam.bf / p.z() : -1.0;
  return true;
}

// `free_keyframes` newest keyframes free, `fixed_keyframes` older ones fixed; each point is kept
// when a free keyframe sees it, with every observation it has in the window.
BundleAdjustmentProblem local_window(int free_keyframes, int fixed_keyframes, int points,
                                     bool stereo) {
  std::mt19937 rng(42);
  BundleAdjustmentProblem problem;
  problem.camera = kitti_camera();
  const int keyframes = free_keyframes + fixed_keyframes;
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 0; k < keyframes; ++k) {
    const bool fixed = k < fixed_keyframes;
    Vec6 delta;
    delta << 0.002 * n(rng), 0.002 * n(rng), 0.002 * n(rng), 0.05 * n(rng), 0.05 * n(rng),
        0.05 * n(rng);
    problem.keyframes.push_back(
        {fixed ? pose_of_keyframe(k) : SE3::exp(delta) * pose_of_keyframe(k), fixed});
  }
  while (static_cast<int>(problem.points.size()) < points) {
    const Vec3 p = street_point(rng, keyframes + 20.0);
    std::vector<BaObservation> seen;
    bool seen_by_free = false;
    for (int k = 0; k < keyframes; ++k) {
      BaObservation o;
      if (!project(problem.camera, pose_of_keyframe(k), p, stereo, rng, o.pixel)) continue;
      o.keyframe = k;
      o.point = static_cast<int>(problem.points.size());
      seen.push_back(o);
      seen_by_free = seen_by_free || k >= fixed_keyframes;
    }
    // Tracking keeps a point for a few keyframes only: a run of 2 to 14 consecutive sightings.
    if (seen.size() > 2) {
      std::uniform_int_distribution<std::size_t> length(2, std::min<std::size_t>(14, seen.size()));
      const std::size_t keep = length(rng);
      std::uniform_int_distribution<std::size_t> first(0, seen.size() - keep);
      const std::size_t start = first(rng);
      seen = std::vector<BaObservation>(seen.begin() + static_cast<std::ptrdiff_t>(start),
                                        seen.begin() + static_cast<std::ptrdiff_t>(start + keep));
      seen_by_free = seen.back().keyframe >= fixed_keyframes;
    }
    if (!seen_by_free || seen.size() < 2) continue;
    problem.points.push_back({p + 0.1 * Vec3(n(rng), n(rng), n(rng)), false});
    problem.observations.insert(problem.observations.end(), seen.begin(), seen.end());
  }
  return problem;
}

void BM_LocalBundleAdjustment(benchmark::State& state) {
  const bool stereo = state.range(0) != 0;
  const BundleAdjustmentProblem problem = local_window(21, 60, 4000, stereo);
  BundleAdjusterOptions options;
  options.num_threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    BundleAdjustmentProblem copy = problem;
    benchmark::DoNotOptimize(bundle_adjust(copy, options));
  }
  state.SetLabel(std::string(stereo ? "stereo" : "mono") + ", 21 free + 60 fixed keyframes, " +
                 std::to_string(problem.points.size()) + " points, " +
                 std::to_string(problem.observations.size()) + " observations");
}
BENCHMARK(BM_LocalBundleAdjustment)
    ->ArgsProduct({{1, 0}, {1, 2}})
    ->ArgNames({"stereo", "threads"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Stereo local BA as the local mapper runs it: one thread, each pass ending below the mapper's
// function tolerance.
void BM_StereoLocalBundleAdjustmentAsMapped(benchmark::State& state) {
  const BundleAdjustmentProblem problem = local_window(21, 60, 4000, true);
  BundleAdjusterOptions options;
  options.function_tolerance = sbaslam::mapping::LocalMapperOptions{}.stereo_ba_function_tolerance;
  int iterations = 0;
  for (auto _ : state) {
    BundleAdjustmentProblem copy = problem;
    const BundleAdjustmentReport report = bundle_adjust(copy, options);
    iterations = report.iterations;
    benchmark::DoNotOptimize(report);
  }
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_StereoLocalBundleAdjustmentAsMapped)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MotionOnlyBundleAdjustment(benchmark::State& state) {
  const bool salient = state.range(0) != 0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const RectifiedCamera cam = kitti_camera();
  std::vector<Vec3> points;
  std::vector<PixelObservation> observations;
  const SE3 truth = pose_of_keyframe(10);
  while (points.size() < 900) {
    const Vec3 p = street_point(rng, 40.0);
    PixelObservation obs;
    if (!project(cam, truth, p, true, rng, obs)) continue;
    // A tenth of the matches wrong by up to 20 px, as in a tracked frame before the outlier test.
    if (unit(rng) < 0.1) {
      obs.u += 40.0 * (unit(rng) - 0.5);
      obs.v += 40.0 * (unit(rng) - 0.5);
    }
    // Salient BA's weights a S^2 + b (a = 256, b = 1): most static structure saturated at 257.
    if (salient) obs.weight = unit(rng) < 0.8 ? 257.0 : 1.0 + 256.0 * std::pow(unit(rng), 2);
    points.push_back(p);
    observations.push_back(obs);
  }
  const PoseOptimizer optimizer(cam);
  Vec6 delta;
  delta << 0.01, -0.01, 0.005, 0.1, 0.05, 0.3;
  for (auto _ : state) {
    SE3 T_cw = SE3::exp(delta) * truth;
    benchmark::DoNotOptimize(optimizer.optimize(T_cw, points, observations));
  }
  state.SetLabel(std::string("900 stereo observations, 4 rounds, ") +
                 (salient ? "salient weights" : "uniform weights"));
}
BENCHMARK(BM_MotionOnlyBundleAdjustment)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("salient")
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
