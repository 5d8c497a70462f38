// Place recognition's query against a growing keyframe database (loop/keyframe_database.h), with
// the shipped vocabulary and real ORB descriptors: the 51 KITTI 06 frames (2000 features each),
// filed again and again up to N keyframes, so that every place recurs as in a city of look-alike
// blocks, the case where many keyframes share enough words to be scored.
//   bench/loop_detection_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sbaslam/core/shipped_file.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/loop/keyframe_database.h"
#include "sbaslam/loop/vocabulary.h"
#include "sbaslam/map/map.h"

namespace {

using sbaslam::loop::BowVector;
using sbaslam::loop::FeatureVector;

constexpr int kKittiFrames = 51;

// The BoWs of the KITTI 06 frames, computed once for every benchmark.
const std::vector<BowVector>& kitti_bows() {
  static const std::vector<BowVector> bows = [] {
    const auto vocabulary = sbaslam::loop::Vocabulary::load(
        sbaslam::shipped_file_path("orb_vocabulary.bin", "ORB vocabulary"));
    sbaslam::OrbSettings settings;
    settings.n_features = 2000;
    sbaslam::feature::OrbExtractor extractor(settings);
    std::vector<BowVector> result;
    for (int i = 0; i < kKittiFrames; ++i) {
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.png", i);
      const cv::Mat image = cv::imread(
          std::string(SBASLAM_SHARED_DIR) + "/data/kitti06_first51/sequences/06/image_0/" + name,
          cv::IMREAD_GRAYSCALE);
      if (image.empty()) return std::vector<BowVector>{};
      sbaslam::feature::OrbFeatures features;
      extractor.extract(image, features);
      BowVector bow;
      FeatureVector unused;
      vocabulary.transform(features.descriptors, bow, unused, 4);
      result.push_back(std::move(bow));
    }
    return result;
  }();
  return bows;
}

void BM_LoopCandidateQuery(benchmark::State& state) {
  const std::vector<BowVector>& bows = kitti_bows();
  if (bows.empty()) {
    state.SkipWithError("cannot read the KITTI 06 frames in ../shared/data");
    return;
  }
  const sbaslam::map::CameraRig rig;
  sbaslam::map::Map map;
  sbaslam::loop::KeyFrameDatabase database;
  const auto filed = static_cast<std::size_t>(state.range(0));
  for (std::size_t i = 0; i < filed; ++i) {
    const auto* kf = map.create_keyframe(i, 0.1 * static_cast<double>(i), sbaslam::SE3(),
                                         std::make_shared<sbaslam::map::Measurements>(), &rig);
    database.add(kf, bows[i % bows.size()]);
  }
  const auto* query = map.create_keyframe(filed, 0.0, sbaslam::SE3(),
                                          std::make_shared<sbaslam::map::Measurements>(), &rig);
  std::size_t candidates = 0;
  for (auto _ : state)
    candidates =
        database.detect_loop_candidates(query, bows[kKittiFrames / 2], {query}, 0.0).size();
  state.counters["candidates"] = static_cast<double>(candidates);
}
BENCHMARK(BM_LoopCandidateQuery)
    ->Arg(100)
    ->Arg(500)
    ->Arg(1000)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
