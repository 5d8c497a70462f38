// sba-slam saliency: make the semantic-gaze dataset (make-dataset) and run the saliency model on a
// folder of images (predict).

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/io/image_io.h"
#include "sbaslam/saliency/saliency_model.h"
#include "sbaslam/saliency/salient_dataset.h"
#include "sbaslam/saliency/stable_dataset.h"

namespace sbaslam::cli {
namespace {
namespace fs = std::filesystem;

struct MakeDatasetArguments {
  std::string sim, images, labels, stable, out;
  saliency::SalientDatasetOptions options;
};

void run_make_dataset(const MakeDatasetArguments& args) {
  if (args.sim.empty() == args.images.empty())
    fail(
        "make-dataset: give either --sim DIR, or --images DIR with --labels DIR or "
        "--stable stable_features.csv");
  if (!args.images.empty() && args.labels.empty() == args.stable.empty())
    fail(
        "make-dataset: --images needs either --labels (a folder of Cityscapes label-id PNGs) or "
        "--stable (the stable_features.csv of 'sba-slam run --export-stable-features')");
  if (!args.sim.empty() && !args.stable.empty())
    fail("make-dataset: --stable goes with --images, not --sim");
  if (args.options.sigma_fraction <= 0)
    fail("--sigma-fraction: must be positive, got {}", args.options.sigma_fraction);
  if (!args.stable.empty()) {
    const int written =
        saliency::write_stable_dataset(args.images, args.stable, args.out, args.options);
    fmt::print("{} self-supervised salient samples written to {}\n", written, args.out);
    return;
  }
  const std::vector<saliency::LabelledImage> pairs =
      args.sim.empty() ? saliency::pairs_from_folders(args.images, args.labels)
                       : saliency::pairs_from_simulation(args.sim);
  const int written = saliency::write_salient_dataset(pairs, args.out, args.options);
  fmt::print("{} salient samples written to {}\n", written, args.out);
}

struct PredictArguments {
  std::string images, out, model;
  bool overlay = false;
  int threads = 1;
};

std::vector<std::string> input_images(const std::string& dir) {
  if (!fs::is_directory(dir)) fail("{}: not a folder", dir);
  std::vector<std::string> names;
  for (const char* ext : {".png", ".jpg", ".jpeg"}) {
    const auto more = io::list_files(dir, ext);
    names.insert(names.end(), more.begin(), more.end());
  }
  std::sort(names.begin(), names.end());
  if (names.empty()) fail("{}: no .png or .jpg images", dir);
  return names;
}

// The paper's figures 3 and 4: a JET colour map blended over the image.
cv::Mat overlay_image(const cv::Mat& gray, const cv::Mat& map) {
  cv::Mat colour, image;
  cv::applyColorMap(map, colour, cv::COLORMAP_JET);
  cv::cvtColor(gray, image, cv::COLOR_GRAY2BGR);
  cv::Mat blended;
  cv::addWeighted(image, 0.5, colour, 0.5, 0.0, blended);
  return blended;
}

void write_png(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) fail("{}: cannot write", path.string());
}

void run_predict(const PredictArguments& args) {
  if (args.threads <= 0) fail("--threads: must be positive, got {}", args.threads);
  const std::vector<std::string> names = input_images(args.images);
  cv::setNumThreads(args.threads);
  saliency::SaliencyModel model(args.model.empty() ? saliency::shipped_model_path() : args.model);
  std::error_code ec;
  fs::create_directories(fs::path(args.out) / (args.overlay ? "overlay" : ""), ec);
  if (ec) fail("{}: cannot create folder: {}", args.out, ec.message());
  std::vector<double> ms;
  for (const std::string& name : names) {
    const std::string path = (fs::path(args.images) / name).string();
    const cv::Mat gray = io::read_gray_image(path);
    const auto start = std::chrono::steady_clock::now();
    const cv::Mat small = model.predict(gray, 0.0, path);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
    cv::Mat map;
    cv::resize(small, map, gray.size(), 0, 0, cv::INTER_LINEAR);
    const std::string png = fs::path(name).replace_extension(".png").string();
    write_png(fs::path(args.out) / png, map);
    if (args.overlay) write_png(fs::path(args.out) / "overlay" / png, overlay_image(gray, map));
  }
  // The first call includes OpenCV dnn's one-time setup; the median ignores it.
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  nlohmann::json timing;
  timing["inference_ms"] = {
      {"median", median}, {"min", sorted.front()}, {"max", sorted.back()}, {"first", ms.front()}};
  timing["input_size"] = {model.input_size().width, model.input_size().height};
  timing["threads"] = args.threads;
  timing["frames"] = names.size();
  timing["model"] = model.path();
  write_output_file((fs::path(args.out) / "timing.json").string(), timing.dump(2) + "\n");
  fmt::print("{} saliency maps written to {} (median {:.2f} ms per frame at {}x{}, {} thread{})\n",
             names.size(), args.out, median, model.input_size().width, model.input_size().height,
             args.threads, args.threads == 1 ? "" : "s");
}

void add_make_dataset(CLI::App& saliency) {
  auto args = std::make_shared<MakeDatasetArguments>();
  CLI::App* cmd = saliency.add_subcommand(
      "make-dataset",
      "semantic-gaze ground truth: geometric cues (ORB, LSD lines, edges) on the 13 static "
      "Cityscapes classes, splatted into density maps plus fixation maps");
  cmd->add_option("--sim", args->sim, "folder written by 'sba-slam simulate' (labels included)");
  cmd->add_option("--images", args->images, "folder of images");
  cmd->add_option("--labels", args->labels,
                  "folder of Cityscapes label-id PNGs named like the images");
  cmd->add_option("--stable", args->stable,
                  "instead of --labels: stable_features.csv of 'sba-slam run "
                  "--export-stable-features' (self-supervised labels; images named as in the csv)");
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_option("--orb-features", args->options.orb_features, "ORB corners per image")
      ->capture_default_str();
  cmd->add_option("--sigma-fraction", args->options.sigma_fraction,
                  "Gaussian sigma as a fraction of the image width")
      ->capture_default_str();
  cmd->callback([args] { run_make_dataset(*args); });
}

void add_predict(CLI::App& saliency) {
  auto args = std::make_shared<PredictArguments>();
  CLI::App* cmd = saliency.add_subcommand(
      "predict", "saliency maps (8-bit PNG, same names) for a folder of images, with timing.json");
  cmd->add_option("--images", args->images, "folder of images")->required();
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_flag("--overlay", args->overlay,
                "also write OUT/overlay/: the map blended over the image");
  cmd->add_option("--threads", args->threads, "OpenCV threads")->capture_default_str();
  cmd->add_option("--model", args->model, "ONNX model (default: the shipped one)");
  cmd->callback([args] { run_predict(*args); });
}

}  // namespace

void add_saliency_command(CLI::App& app) {
  CLI::App* saliency =
      app.add_subcommand("saliency", "saliency dataset maker and saliency model inference");
  saliency->require_subcommand(1);
  add_make_dataset(*saliency);
  add_predict(*saliency);
}

}  // namespace sbaslam::cli
