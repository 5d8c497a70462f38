// ORB front-end timings on the shared real images, ours beside OpenCV's cv::ORB in the same
// process: one EuRoC image (752x480, 1200 features), one KITTI image (1226x370, 2000 features),
// and a KITTI stereo pair (both images extracted in parallel + stereo matching); the descriptor
// blur alone, ours beside cv::GaussianBlur.
//   bench/feature_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "sbaslam/feature/gaussian_blur.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/match/orb_matcher.h"

namespace {

const std::string kData = std::string(SBASLAM_SHARED_DIR) + "/data";
const std::string kEuroc = kData + "/euroc_v101_micro/mav0/cam0/data/1403715273262142976.png";
const std::string kKittiLeft = kData + "/stereo_pairs/kitti06_frame12/left.png";
const std::string kKittiRight = kData + "/stereo_pairs/kitti06_frame12/right.png";

cv::Mat load(const std::string& path, benchmark::State& state) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) state.SkipWithError(("cannot read " + path).c_str());
  return image;
}

sbaslam::OrbSettings orb_settings(int n_features) {
  sbaslam::OrbSettings s;
  s.n_features = n_features;
  return s;
}

void run_ours(benchmark::State& state, const std::string& path, int n_features) {
  const cv::Mat image = load(path, state);
  sbaslam::feature::OrbExtractor extractor(orb_settings(n_features));
  sbaslam::feature::OrbFeatures features;
  for (auto _ : state) {
    extractor.extract(image, features);
    benchmark::DoNotOptimize(features.descriptors.data);
  }
  state.counters["features"] = static_cast<double>(features.size());
}

void run_opencv(benchmark::State& state, const std::string& path, int n_features) {
  const cv::Mat image = load(path, state);
  const auto orb = cv::ORB::create(n_features, 1.2f, 8);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["features"] = static_cast<double>(keypoints.size());
}

void BM_OursEuroc(benchmark::State& state) {
  run_ours(state, kEuroc, 1200);
}
void BM_OpenCvOrbEuroc(benchmark::State& state) {
  run_opencv(state, kEuroc, 1200);
}
void BM_OursKitti(benchmark::State& state) {
  run_ours(state, kKittiLeft, 2000);
}
void BM_OpenCvOrbKitti(benchmark::State& state) {
  run_opencv(state, kKittiLeft, 2000);
}

// KITTI 04-12 calibration (the kitti06_frame12 pair).
const sbaslam::StereoRig kKittiRig(sbaslam::PinholeIntrinsics{707.0912, 707.0912, 601.8873,
                                                              183.1104},
                                   379.8145 / 707.0912);

void BM_OursKittiStereoPair(benchmark::State& state) {
  const cv::Mat left = load(kKittiLeft, state), right = load(kKittiRight, state);
  sbaslam::feature::StereoExtractor stereo(orb_settings(2000), kKittiRig);
  sbaslam::feature::StereoFeatures out;
  for (auto _ : state) {
    stereo.extract(left, right, out);
    benchmark::DoNotOptimize(out.matches.depth.data());
  }
  state.counters["stereo_matches"] = out.matches.count();
}

void BM_OpenCvOrbKittiPairSequential(benchmark::State& state) {
  const cv::Mat left = load(kKittiLeft, state), right = load(kKittiRight, state);
  const auto orb = cv::ORB::create(2000, 1.2f, 8);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  for (auto _ : state) {
    orb->detectAndCompute(left, cv::noArray(), kl, dl);
    orb->detectAndCompute(right, cv::noArray(), kr, dr);
    benchmark::DoNotOptimize(dr.data);
  }
}

void BM_StereoMatchingOnlyKitti(benchmark::State& state) {
  const cv::Mat left = load(kKittiLeft, state), right = load(kKittiRight, state);
  sbaslam::feature::OrbExtractor l(orb_settings(2000)), r(orb_settings(2000));
  const auto fl = l.extract(left);
  const auto fr = r.extract(right);
  for (auto _ : state) {
    auto matches =
        sbaslam::feature::match_stereo(fl, fr, l.pyramid(), r.pyramid(), l.levels(), kKittiRig);
    benchmark::DoNotOptimize(matches.depth.data());
  }
}

void BM_BruteForce2000x2000(benchmark::State& state) {
  const cv::Mat left = load(kKittiLeft, state), right = load(kKittiRight, state);
  sbaslam::feature::OrbExtractor extractor(orb_settings(2000));
  const auto a = extractor.extract(left);
  const auto b = extractor.extract(right);
  for (auto _ : state) {
    auto matches = sbaslam::match::match_brute_force(a.descriptors, b.descriptors);
    benchmark::DoNotOptimize(matches.data());
  }
}

// The descriptor blur of one KITTI image: ours (bit-exact with OpenCV's) and cv::GaussianBlur.
void BM_BlurOursKitti(benchmark::State& state) {
  const cv::Mat image = load(kKittiLeft, state);
  sbaslam::feature::GaussianBlur7 blur;
  cv::Mat out;
  for (auto _ : state) {
    blur.apply(image, out);
    benchmark::DoNotOptimize(out.data);
  }
}

void BM_BlurOpenCvKitti(benchmark::State& state) {
  const cv::Mat image = load(kKittiLeft, state);
  cv::Mat out;
  for (auto _ : state) {
    cv::GaussianBlur(image, out, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
    benchmark::DoNotOptimize(out.data);
  }
}

BENCHMARK(BM_OursEuroc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OpenCvOrbEuroc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OursKitti)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OpenCvOrbKitti)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OursKittiStereoPair)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OpenCvOrbKittiPairSequential)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StereoMatchingOnlyKitti)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BruteForce2000x2000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BlurOursKitti)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BlurOpenCvKitti)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
