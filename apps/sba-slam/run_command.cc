// sba-slam run: SLAM on a dataset as distributed (KITTI, EuRoC, TUM), writing the trajectory,
// keyframes, timing and a run record into --out.

#include <fmt/format.h>

#include <iostream>

#include "commands.h"
#include "sbaslam/runner.h"

namespace sbaslam::cli {

void add_run_command(CLI::App& app) {
  auto config = std::make_shared<RunConfig>();
  auto seed = std::make_shared<std::uint64_t>(0);
  CLI::App* run = app.add_subcommand("run", "Run SLAM on a dataset and write its trajectory");
  run->add_option("--settings", config->settings_path, "ORB-SLAM3 settings yaml")->required();
  run->add_option("--dataset", config->dataset_kind, "Dataset layout")
      ->required()
      ->check(CLI::IsMember({"kitti", "euroc", "tum"}));
  run->add_option("--path", config->dataset_path,
                  "KITTI: .../sequences/XX; EuRoC: the folder holding mav0/; TUM: the sequence")
      ->required();
  run->add_option("--sensor", config->sensor,
                  "Camera setup (rgbd: the left images with their depth images)")
      ->check(CLI::IsMember({"stereo", "mono", "rgbd"}))
      ->capture_default_str();
  run->add_option("--out", config->out_dir, "Output folder")->required();
  CLI::Option* seed_option =
      run->add_option("--seed", *seed, "Seed of every random choice (overrides System.seed)");
  run->add_flag("--deterministic", config->deterministic,
                "Tracking and mapping in lock-step on one thread: bit-identical reruns");
  auto saliency = std::make_shared<std::string>();
  CLI::Option* saliency_option =
      run->add_option("--saliency", *saliency,
                      "Saliency source for Salient BA: none (uniform), model (the shipped ONNX "
                      "model) or a folder of precomputed maps named like the images; default: the "
                      "settings' Saliency.source");
  auto loop_closing = std::make_shared<std::string>();
  CLI::Option* loop_option = run->add_option("--loop-closing", *loop_closing,
                                             "Loop closing on or off (overrides the settings' "
                                             "loopClosing, which is on when absent, "
                                             "as in ORB-SLAM3)")
                                 ->check(CLI::IsMember({"on", "off"}));
  run->add_option("--max-frames", config->max_frames, "Stop after this many frames (0: all)");
  run->add_flag("--realtime", config->realtime,
                "Feed frames at the dataset's rate (by timestamp), like a live camera and like "
                "ORB-SLAM3's examples; default: as fast as possible");
  run->add_flag("--export-stable-features", config->export_stable_features,
                "Also write stable_features.csv: the keypoints of long-lived, low-error map points "
                "(self-supervised saliency labels for 'saliency make-dataset --stable')");
  run->add_option("--stable-min-observations", config->stable_gate.min_observations,
                  "Keyframes that must observe a stable point")
      ->capture_default_str();
  run->add_option("--stable-max-chi2", config->stable_gate.max_chi2,
                  "Gate on the squared mean reprojection error in level sigmas")
      ->capture_default_str();
  auto load_map = std::make_shared<std::string>();
  CLI::Option* load_option =
      run->add_option("--load-map", *load_map,
                      "Start from a map saved by --save-map: relocalise in it, then map on "
                      "(overrides System.LoadAtlasFromFile)");
  auto save_map = std::make_shared<std::string>();
  CLI::Option* save_option =
      run->add_option("--save-map", *save_map,
                      "Write the map at the end of the run (overrides System.SaveAtlasToFile)");
  run->add_flag("--localization-only", config->localization_only,
                "ORB-SLAM3's localization mode: track in the loaded map without changing it");
  run->callback([config, seed, seed_option, saliency, saliency_option, loop_closing, loop_option,
                 load_map, load_option, save_map, save_option] {
    if (seed_option->count() > 0) config->seed = *seed;
    if (load_option->count() > 0) config->load_map = *load_map;
    if (save_option->count() > 0) config->save_map = *save_map;
    if (saliency_option->count() > 0) config->saliency = *saliency;
    if (loop_option->count() > 0) config->loop_closing = *loop_closing == "on";
    const RunResult r = run_sequence(*config);
    std::cout << fmt::format(
        "{}frames {}  tracked {}  keyframes {}  map points {}  maps {}  loops closed {}\n"
        "tracking {:.1f} ms/frame (median)  local BA {:.1f} ms (median)\n"
        "wrote {}/trajectory.tum, keyframes.tum, timing.json, run.json\n",
        r.status == "ok" ? "" : r.status + "\n", r.frames, r.frames_tracked, r.keyframes,
        r.map_points, r.maps, r.loops_closed, r.tracking_median_ms, r.local_ba_median_ms,
        config->out_dir);
    if (!r.saved_map.empty())
      std::cout << fmt::format("wrote the map to {} ({} keyframes)\n", r.saved_map,
                               r.saved_keyframes);
    if (config->export_stable_features)
      std::cout << fmt::format(
          "wrote {}/stable_features.csv: {} observations of {} stable points\n", config->out_dir,
          r.stable_feature_rows, r.stable_points);
    // A run stopped by a signal wrote its outputs but exits as shells expect of that signal.
    if (r.stop_signal) throw CLI::RuntimeError(128 + r.stop_signal);
  });
}

}  // namespace sbaslam::cli
