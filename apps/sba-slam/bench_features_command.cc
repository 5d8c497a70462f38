// sba-slam bench-features: times our ORB extraction, OpenCV's cv::ORB on the same images in the
// same process, and (with --right) stereo extraction of both images in parallel plus stereo
// matching. Prints a table; --json writes the medians.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <opencv2/features2d.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/core/stereo_rectifier.h"
#include "sbaslam/feature/orb_extractor.h"
#include "sbaslam/feature/stereo_matcher.h"
#include "sbaslam/io/image_io.h"

namespace sbaslam::cli {
namespace {

struct BenchFeaturesArguments {
  std::string settings_path;
  std::string left_dir;
  std::string right_dir;
  std::string json_path;
  int repeat = 3;
  int max_images = 50;
};

struct Samples {
  std::vector<double> ms;
  double quantile(double q) const {
    if (ms.empty()) return 0.0;
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    return sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(q * sorted.size()))];
  }
  nlohmann::json to_json() const {
    return {{"median", quantile(0.5)}, {"p90", quantile(0.9)}, {"samples", ms.size()}};
  }
};

template <typename F>
double time_ms(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

std::vector<cv::Mat> read_images(const std::string& dir, const std::vector<std::string>& names) {
  std::vector<cv::Mat> images;
  for (const std::string& name : names) images.push_back(io::read_gray_image(dir + "/" + name));
  for (const cv::Mat& image : images)
    if (image.size() != images.front().size())
      fail("{}: images differ in size ({}x{} vs {}x{})", dir, image.cols, image.rows,
           images.front().cols, images.front().rows);
  return images;
}

// The rig and images the stereo timing runs on: rectified at load time when the settings
// describe an unrectified pair (EuRoC), as the SLAM system would.
StereoRig prepare_stereo(const Settings& settings, std::vector<cv::Mat>& left,
                         std::vector<cv::Mat>& right) {
  if (!settings.stereo.enabled)
    fail("{}: --right needs stereo settings (Camera.bf or Stereo.T_c1_c2)", settings.path);
  if (!settings.stereo.right) {
    const auto& k = settings.camera.intrinsics;
    return StereoRig(k, settings.stereo.baseline);
  }
  const StereoRectifier rectifier = StereoRectifier::from_settings(settings);
  for (std::size_t i = 0; i < left.size(); ++i) {
    cv::Mat l, r;
    rectifier.rectify(left[i], right[i], l, r);
    left[i] = l;
    right[i] = r;
  }
  return rectifier.rig();
}

void run(const BenchFeaturesArguments& args) {
  const Settings settings = load_settings(args.settings_path);
  std::vector<std::string> names = io::list_files(args.left_dir, ".png");
  if (names.empty()) fail("{}: no .png images", args.left_dir);
  if (static_cast<int>(names.size()) > args.max_images) names.resize(args.max_images);
  const std::vector<cv::Mat> left = read_images(args.left_dir, names);
  const bool stereo = !args.right_dir.empty();
  std::vector<cv::Mat> stereo_left, stereo_right;
  StereoRig rig;
  if (stereo) {
    stereo_left = left;
    stereo_right = read_images(args.right_dir, names);
    if (stereo_right.front().size() != left.front().size())
      fail("{}: right images differ in size from the left ones", args.right_dir);
    rig = prepare_stereo(settings, stereo_left, stereo_right);
  }

  const OrbSettings& orb = settings.orb;
  feature::OrbExtractor ours(orb);
  const cv::Ptr<cv::ORB> opencv =
      cv::ORB::create(orb.n_features, static_cast<float>(orb.scale_factor), orb.n_levels);
  std::unique_ptr<feature::StereoExtractor> stereo_extractor;
  if (stereo) stereo_extractor = std::make_unique<feature::StereoExtractor>(orb, rig);

  Samples ours_ms, opencv_ms, stereo_ms;
  double ours_count = 0, opencv_count = 0, stereo_count = 0;
  feature::OrbFeatures features;
  feature::StereoFeatures stereo_features;
  std::vector<cv::KeyPoint> cv_keypoints;
  cv::Mat cv_descriptors;
  // Round 0 warms caches and buffers and is not recorded.
  for (int round = 0; round <= args.repeat; ++round) {
    for (std::size_t i = 0; i < left.size(); ++i) {
      const double t_ours = time_ms([&] { ours.extract(left[i], features); });
      const double t_cv = time_ms(
          [&] { opencv->detectAndCompute(left[i], cv::noArray(), cv_keypoints, cv_descriptors); });
      if (round == 0) continue;
      ours_ms.ms.push_back(t_ours);
      opencv_ms.ms.push_back(t_cv);
      ours_count += static_cast<double>(features.size());
      opencv_count += static_cast<double>(cv_keypoints.size());
    }
    if (!stereo) continue;
    for (std::size_t i = 0; i < stereo_left.size(); ++i) {
      const double t = time_ms(
          [&] { stereo_extractor->extract(stereo_left[i], stereo_right[i], stereo_features); });
      if (round == 0) continue;
      stereo_ms.ms.push_back(t);
      stereo_count += stereo_features.matches.count();
    }
  }
  const double n = static_cast<double>(ours_ms.ms.size());
  const cv::Size size = left.front().size();

  fmt::print("bench-features: {} images of {}x{}, {} rounds, nFeatures {}, OpenCV threads {}\n",
             left.size(), size.width, size.height, args.repeat, orb.n_features,
             cv::getNumThreads());
  fmt::print("{:<34} {:>10} {:>10} {:>12}\n", "", "median ms", "p90 ms", "features");
  fmt::print("{:<34} {:>10.2f} {:>10.2f} {:>12.0f}\n", "ours (one image)", ours_ms.quantile(0.5),
             ours_ms.quantile(0.9), ours_count / n);
  fmt::print("{:<34} {:>10.2f} {:>10.2f} {:>12.0f}\n", "cv::ORB (one image)",
             opencv_ms.quantile(0.5), opencv_ms.quantile(0.9), opencv_count / n);
  if (stereo)
    fmt::print("{:<34} {:>10.2f} {:>10.2f} {:>12.0f}\n", "ours stereo pair + matching",
               stereo_ms.quantile(0.5), stereo_ms.quantile(0.9), stereo_count / n);

  if (args.json_path.empty()) return;
  nlohmann::json j;
  j["ours_ms"] = ours_ms.to_json();
  j["opencv_orb_ms"] = opencv_ms.to_json();
  if (stereo) {
    j["stereo_pair_ms"] = stereo_ms.to_json();
    j["stereo_matches_mean"] = stereo_count / n;
  }
  j["features"] = orb.n_features;
  j["ours_features_mean"] = ours_count / n;
  j["opencv_features_mean"] = opencv_count / n;
  j["image_size"] = {size.width, size.height};
  j["images"] = left.size();
  j["repeat"] = args.repeat;
  j["opencv_threads"] = cv::getNumThreads();
  write_output_file(args.json_path, j.dump(2) + "\n");
}

}  // namespace

void add_bench_features_command(CLI::App& app) {
  auto args = std::make_shared<BenchFeaturesArguments>();
  CLI::App* cmd = app.add_subcommand(
      "bench-features", "Time ORB extraction (ours vs cv::ORB) and stereo matching on images");
  cmd->add_option("--settings", args->settings_path, "ORB-SLAM3 settings yaml")->required();
  cmd->add_option("--left", args->left_dir, "Folder of left (or mono) .png images")->required();
  cmd->add_option("--right", args->right_dir,
                  "Folder of right images with the same file names (times stereo)");
  cmd->add_option("--json", args->json_path, "Write the results as JSON");
  cmd->add_option("--repeat", args->repeat, "Timed passes over the images")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--max-images", args->max_images, "Use at most this many images")
      ->check(CLI::Range(1, 100000));
  cmd->callback([args] { run(*args); });
}

}  // namespace sbaslam::cli
