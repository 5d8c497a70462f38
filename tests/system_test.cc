// End-to-end SLAM on the real fixtures. EuRoC: the drone stands still in these 95 frames, so a
// stereo estimate must not drift, a monocular one must refuse to initialise, and deterministic
// mode must reproduce itself bit for bit. KITTI 06: fast forward motion, monocular. And one
// synthetic segment: a city corner, where the constant-velocity guess fails.

#include "sbaslam/system.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "helper/expect_error.h"
#include "helper/fixture_copy.h"
#include "helper/fixture_runs.h"
#include "helper/orbslam2_stereo.h"
#include "helper/rendered_run.h"
#include "helper/temp_dir.h"
#include "sbaslam/core/error.h"
#include "sbaslam/core/shipped_file.h"
#include "sbaslam/eval/evaluator.h"
#include "sbaslam/io/trajectory_io.h"
#include "sbaslam/runner.h"
#include "sbaslam/saliency/saliency_model.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"

namespace sbaslam {
namespace {

const std::string kEuroc = std::string(SBASLAM_SHARED_DIR) + "/data/euroc_v101_micro";

RunConfig euroc_stereo_config(const std::string& out, std::size_t max_frames) {
  RunConfig config;
  config.settings_path = std::string(SBASLAM_SOURCE_DIR) + "/config/EuRoC_stereo.yaml";
  config.dataset_kind = "euroc";
  config.dataset_path = kEuroc;
  config.sensor = "stereo";
  config.out_dir = out;
  config.deterministic = true;
  config.seed = 7;
  config.max_frames = max_frames;
  config.progress = false;
  return config;
}

using test::kitti06_mono_config;
using test::kKitti06;

TEST(System, StaticEurocStereoTracksEveryFrameWithoutDrift) {
  test::TempDir dir;
  const RunResult result = run_sequence(euroc_stereo_config(dir.path().string(), 0));
  EXPECT_EQ(result.frames, 95u);
  EXPECT_EQ(result.frames_tracked, 95u);
  EXPECT_EQ(result.maps, 1);
  double max_offset = 0.0;
  for (const SE3& pose : result.trajectory.poses)
    max_offset = std::max(max_offset, pose.translation().norm());
  EXPECT_LT(max_offset, 0.005);  // the camera stays within 5 mm of its start

  eval::EvalSettings ape;
  ape.metric = eval::Metric::kApe;
  ape.reference_path = kEuroc + "/groundtruth/body_tum.txt";
  ape.estimate_path = dir.file("trajectory.tum");
  ape.format = io::TrajectoryFormat::kTum;
  ape.align = eval::AlignmentMode::kSe3;
  ape.ref_body_to_cam_yaml = kEuroc + "/mav0/cam0/sensor.yaml";
  const eval::EvalResult ate = eval::evaluate(ape);
  EXPECT_EQ(ate.stats.n, 95u);
  EXPECT_LT(ate.stats.rmse, 0.001);

  // The same poses in EuRoC's csv layout (nanosecond stamps).
  const Trajectory csv = io::read_euroc_groundtruth(dir.file("trajectory.csv"));
  ASSERT_EQ(csv.size(), result.trajectory.size());
  EXPECT_NEAR(csv.stamps.back(), result.trajectory.stamps.back(), 1e-6);
  EXPECT_LT((csv.poses.back().translation() - result.trajectory.poses.back().translation()).norm(),
            1e-9);
}

TEST(System, DeterministicRunsAreByteIdentical) {
  test::TempDir a, b;
  run_sequence(euroc_stereo_config(a.path().string(), 30));
  run_sequence(euroc_stereo_config(b.path().string(), 30));
  const std::string first = test::read_text_file(a.file("trajectory.tum"));
  EXPECT_GT(first.size(), 100u);
  EXPECT_EQ(first, test::read_text_file(b.file("trajectory.tum")));
  EXPECT_EQ(test::read_text_file(a.file("keyframes.tum")),
            test::read_text_file(b.file("keyframes.tum")));
}

// ORB-SLAM2's stereo file (LEFT.* / RIGHT.*) calibrates a recording without sensor.yaml as the
// sensor.yaml files would: at alpha 0 its rectification is theirs, so the images are the same to
// the byte and the poses to rounding (the rectification's rotation comes from another product of
// the same T_BS).
TEST(System, OrbSlam2StereoFileCalibratesARecordingWithoutSensorYaml) {
  test::TempDir dir;
  const std::string root = test::copy_euroc_subset(dir.file("data"), 30, true);
  test::write_text_file(dir.file("orbslam2.yaml"),
                        test::orbslam2_stereo_settings(test::euroc_fixture_rectification(0.0)));
  RunConfig config = euroc_stereo_config(dir.file("with"), 0);
  config.settings_path = dir.file("orbslam2.yaml");
  config.dataset_path = root;
  run_sequence(config);
  std::filesystem::remove(root + "/mav0/cam0/sensor.yaml");
  std::filesystem::remove(root + "/mav0/cam1/sensor.yaml");
  config.out_dir = dir.file("without");
  const RunResult result = run_sequence(config);
  EXPECT_EQ(result.frames_tracked, 30u);
  const Trajectory with = io::read_tum_trajectory(dir.file("with/trajectory.tum"));
  const Trajectory without = io::read_tum_trajectory(dir.file("without/trajectory.tum"));
  ASSERT_EQ(with.size(), 30u);
  ASSERT_EQ(without.size(), 30u);
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_EQ(without.stamps[i], with.stamps[i]);
    EXPECT_LT((without.poses[i].inverse() * with.poses[i]).log().norm(), 1e-12) << i;
  }
}

// Salient BA with the shipped model is the default (issue 7): a run given no --saliency, on a
// shipped settings file, uses the model and says so in run.json with its ONNX file and depth.
TEST(System, DefaultRunIsSalientAndRecordsItsSaliencyInRunJson) {
  test::TempDir dir;
  RunConfig config = euroc_stereo_config(dir.path().string(), 10);
  ASSERT_FALSE(config.saliency.has_value());
  const RunResult result = run_sequence(config);
  EXPECT_EQ(result.frames_tracked, 10u);
  const nlohmann::json run = nlohmann::json::parse(test::read_text_file(dir.file("run.json")));
  const nlohmann::json& saliency = run.at("saliency");
  EXPECT_EQ(saliency.at("source"), "model");
  EXPECT_EQ(saliency.at("model"), saliency::shipped_model_path());
  EXPECT_EQ(saliency.at("depth"), "auto");
  // config/EuRoC_stereo.yaml: a = 256, b = 1, local and full BA's largest weight 16.
  EXPECT_DOUBLE_EQ(saliency.at("map_ba_weight_scale").get<double>(), 16.0 / 257.0);
}

// Loop closing is on by default (ORB-SLAM3's settings file has no `loopClosing` key): every
// keyframe local mapping finishes goes to the loop closer, run.json says so, and a drive that
// never comes back (KITTI 06's first 51 frames) closes no loop and leaves the trajectory exactly
// as with `--loop-closing off`.
TEST(System, LoopClosingChecksEveryKeyframeAndLeavesALooplessRunAsItWas) {
  test::TempDir on, off;
  RunConfig config = kitti06_mono_config(on.path().string(), true);
  ASSERT_EQ(test::read_text_file(config.settings_path).find("loopClosing"), std::string::npos);
  const RunResult result = run_sequence(config);
  config.loop_closing = false;
  config.out_dir = off.path().string();
  run_sequence(config);

  EXPECT_EQ(result.loops_closed, 0u);
  const nlohmann::json loop =
      nlohmann::json::parse(test::read_text_file(on.file("run.json"))).at("loop_closing");
  EXPECT_TRUE(loop.at("enabled").get<bool>());
  EXPECT_EQ(loop.at("vocabulary"), shipped_file_path("orb_vocabulary.bin", "ORB vocabulary"));
  // The last keyframes may still be queued for local mapping when it stops.
  EXPECT_GE(loop.at("keyframes_checked").get<std::size_t>() + 2, result.keyframes);
  EXPECT_TRUE(loop.at("loops").empty());
  EXPECT_EQ(test::read_text_file(on.file("trajectory.tum")),
            test::read_text_file(off.file("trajectory.tum")));
  const nlohmann::json loop_off =
      nlohmann::json::parse(test::read_text_file(off.file("run.json"))).at("loop_closing");
  EXPECT_FALSE(loop_off.at("enabled").get<bool>());
}

TEST(System, LoopClosingWithAMissingVocabularyFailsNamingTheFile) {
  test::TempDir dir;
  const std::string settings = dir.file("settings.yaml");
  std::ofstream(settings) << test::read_text_file(std::string(SBASLAM_SOURCE_DIR) +
                                                  "/config/KITTI04-12.yaml")
                          << "\nloopClosing: 1\nLoopClosing.vocabulary: \"" << dir.file("none.bin")
                          << "\"\n";
  RunConfig config = kitti06_mono_config(dir.file("out"), true);
  config.settings_path = settings;
  config.max_frames = 3;
  test::expect_error_naming([&] { run_sequence(config); }, dir.file("none.bin"));
}

// Monocular frames predict their saliency map as one of the extraction's parallel tasks; the
// deterministic mode must still reproduce itself bit for bit, and the map must reach the weights.
TEST(System, MonocularSalientRunsPredictAmongExtractionTasksAndStayDeterministic) {
  test::TempDir a, b, uniform;
  RunConfig config = kitti06_mono_config(a.path().string(), true);
  config.max_frames = 20;
  config.saliency = "model";
  const RunResult first = run_sequence(config);
  config.out_dir = b.path().string();
  run_sequence(config);
  config.saliency = "none";
  config.out_dir = uniform.path().string();
  run_sequence(config);

  ASSERT_GT(first.frames_tracked, 10u);
  const std::string trajectory = test::read_text_file(a.file("trajectory.tum"));
  EXPECT_EQ(trajectory, test::read_text_file(b.file("trajectory.tum")));
  EXPECT_EQ(test::read_text_file(a.file("keyframes.tum")),
            test::read_text_file(b.file("keyframes.tum")));
  // The weights changed the solution: the map was predicted, not left empty by the thread.
  EXPECT_NE(trajectory, test::read_text_file(uniform.file("trajectory.tum")));
  const nlohmann::json timing = nlohmann::json::parse(test::read_text_file(a.file("timing.json")));
  EXPECT_GT(timing.at("saliency_ms").at("median").get<double>(), 0.0);
  // Uniform BA keeps every weight 1 in local BA too.
  const nlohmann::json run = nlohmann::json::parse(test::read_text_file(uniform.file("run.json")));
  EXPECT_DOUBLE_EQ(run.at("saliency").at("map_ba_weight_scale").get<double>(), 1.0);
}

TEST(System, RealtimePlaybackTakesAtLeastTheRecordedTime) {
  test::TempDir dir;
  RunConfig config = euroc_stereo_config(dir.path().string(), 21);
  config.deterministic = false;
  config.realtime = true;
  const auto start = std::chrono::steady_clock::now();
  const RunResult result = run_sequence(config);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(result.trajectory.size(), 21u);
  // EuRoC is 20 Hz: the 21st frame is due one second after the first.
  const double recorded = result.trajectory.stamps.back() - result.trajectory.stamps.front();
  EXPECT_NEAR(recorded, 1.0, 0.01);
  EXPECT_GE(wall, recorded);
  EXPECT_EQ(result.frames_tracked, 21u);
}

TEST(System, StaticEurocMonocularRefusesToInitialiseAndStillWritesItsFiles) {
  test::TempDir dir;
  RunConfig config = euroc_stereo_config(dir.path().string(), 0);
  config.settings_path = std::string(SBASLAM_SOURCE_DIR) + "/config/EuRoC_mono.yaml";
  config.sensor = "mono";
  const RunResult result = run_sequence(config);
  EXPECT_EQ(result.frames, 95u);
  EXPECT_EQ(result.frames_tracked, 0u);
  EXPECT_EQ(result.maps, 0);
  EXPECT_NE(result.status.find("not initialised: insufficient parallax"), std::string::npos)
      << result.status;
  const std::string run_json = test::read_text_file(dir.file("run.json"));
  EXPECT_NE(run_json.find("\"frames_tracked\": 0"), std::string::npos);
  EXPECT_NE(run_json.find("insufficient parallax"), std::string::npos);
  EXPECT_EQ(test::read_text_file(dir.file("trajectory.tum")).find('\n'),
            test::read_text_file(dir.file("trajectory.tum")).size() - 1);  // header line only
}

// The error of a run of the fixture `kind`/`path` with `sensor`, or "" when it did not fail.
std::string run_error(const std::string& settings, const std::string& kind, const std::string& path,
                      const std::string& sensor) {
  test::TempDir dir;
  RunConfig config;
  config.settings_path = std::string(SBASLAM_SOURCE_DIR) + "/config/" + settings;
  config.dataset_kind = kind;
  config.dataset_path = std::string(SBASLAM_SHARED_DIR) + "/data/" + path;
  config.sensor = sensor;
  config.out_dir = dir.path().string();
  config.progress = false;
  try {
    run_sequence(config);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(System, StereoOnADatasetWithoutRightImagesFailsNamingTheFolder) {
  const std::string path = "kitti06_first51/sequences/06";
  EXPECT_EQ(run_error("KITTI04-12.yaml", "kitti", path, "stereo"),
            std::string(SBASLAM_SHARED_DIR) + "/data/" + path +
                ": --sensor stereo needs right images, and this kitti dataset has none");
}

TEST(System, RgbdOnADatasetWithoutDepthImagesFailsNamingTheFolder) {
  const std::string path = "euroc_v101_micro";
  EXPECT_EQ(run_error("EuRoC_stereo.yaml", "euroc", path, "rgbd"),
            std::string(SBASLAM_SHARED_DIR) + "/data/" + path +
                ": --sensor rgbd needs depth images, and this euroc dataset has none");
}

// The rendered depth (exact to 1/256 m) as an RGB-D sensor: every frame tracked, at the true
// scale and about as precise frame to frame as the stereo run of the same frames (RPE measured:
// 0.0084 m RGB-D, 0.0069 m stereo; without depth the scale would be arbitrary). Which of the two
// is lower over 40 frames is noise: over 300 frames RGB-D has 0.0080 m, stereo 0.0087 m.
TEST(System, RgbdTracksARenderedCityDriveFromItsDepthImages) {
  test::TempDir dir;
  test::render_city_loop(dir, 40);

  double rpe_rmse[2] = {0.0, 0.0};
  for (const std::string sensor : {"stereo", "rgbd"}) {
    RunConfig config = test::rendered_kitti_run(dir);
    config.sensor = sensor;
    config.out_dir = dir.file("out_" + sensor);
    const RunResult result = run_sequence(config);
    EXPECT_EQ(result.frames_tracked, 40u) << sensor;
    EXPECT_EQ(result.maps, 1) << sensor;
    eval::EvalSettings rpe;
    rpe.metric = eval::Metric::kRpe;
    rpe.reference_path = dir.file("data/poses/00.txt");
    rpe.estimate_path = config.out_dir + "/trajectory.kitti";
    rpe.format = io::TrajectoryFormat::kKitti;
    rpe_rmse[sensor == "rgbd"] = eval::evaluate(rpe).stats.rmse;
  }
  EXPECT_LT(rpe_rmse[0], 0.012);
  EXPECT_LT(rpe_rmse[1], 0.012);
  std::printf("RPE 1 frame: stereo %.4f m, rgbd %.4f m\n", rpe_rmse[0], rpe_rmse[1]);

  // The same frames in the TUM RGB-D layout (rgb.txt, depth.txt) give the same trajectory.
  const std::filesystem::path sequence = dir.file("data/sequences/00");
  const std::filesystem::path tum = dir.file("tum");
  std::filesystem::create_directories(tum / "rgb");
  std::filesystem::create_directories(tum / "depth");
  std::ifstream times(sequence / "times.txt");
  std::ofstream rgb_list(tum / "rgb.txt"), depth_list(tum / "depth.txt");
  std::string stamp;
  for (int i = 0; times >> stamp; ++i) {
    const std::string name = fmt::format("{:06d}.png", i);
    std::filesystem::copy_file(sequence / "image_0" / name, tum / "rgb" / name);
    std::filesystem::copy_file(sequence / "depth" / name, tum / "depth" / name);
    rgb_list << stamp << " rgb/" << name << "\n";
    depth_list << stamp << " depth/" << name << "\n";
  }
  rgb_list.close();
  depth_list.close();
  RunConfig config = test::rendered_kitti_run(dir);
  config.dataset_kind = "tum";
  config.dataset_path = tum.string();
  config.sensor = "rgbd";
  config.out_dir = dir.file("out_tum");
  EXPECT_EQ(run_sequence(config).frames_tracked, 40u);
  const Trajectory from_kitti = io::read_tum_trajectory(dir.file("out_rgbd/trajectory.tum"));
  const Trajectory from_tum = io::read_tum_trajectory(dir.file("out_tum/trajectory.tum"));
  ASSERT_EQ(from_tum.size(), from_kitti.size());
  for (std::size_t i = 0; i < from_tum.size(); ++i)
    EXPECT_LT((from_tum.poses[i].matrix() - from_kitti.poses[i].matrix()).norm(), 1e-9) << i;
}

void expect_kitti_monocular_tracks_every_frame_after_an_early_start(bool deterministic) {
  test::TempDir dir;
  const RunConfig config = kitti06_mono_config(dir.path().string(), deterministic);
  const RunResult result = run_sequence(config);
  ASSERT_EQ(result.maps, 1);
  ASSERT_FALSE(result.trajectory.empty());
  // Ground truth to TUM through times.txt, for the Sim3-aligned ATE.
  const Trajectory gt = io::read_kitti_trajectory(kKitti06 + "/poses/06.txt");
  Trajectory gt_timed;
  std::ifstream times(config.dataset_path + "/times.txt");
  for (std::size_t i = 0; i < gt.size(); ++i) {
    double t = 0.0;
    times >> t;
    gt_timed.push_back(t, gt.poses[i]);
  }
  io::write_tum_trajectory(dir.file("gt.tum"), gt_timed);

  // The first pose comes within the first 10 frames, and every later frame has one.
  const auto first =
      std::find(gt_timed.stamps.begin(), gt_timed.stamps.end(), result.trajectory.stamps.front());
  ASSERT_NE(first, gt_timed.stamps.end());
  const auto first_index = static_cast<std::size_t>(first - gt_timed.stamps.begin());
  EXPECT_LT(first_index, 10u);
  EXPECT_EQ(result.frames_tracked, 51u - first_index);

  eval::EvalSettings ape;
  ape.metric = eval::Metric::kApe;
  ape.reference_path = dir.file("gt.tum");
  ape.estimate_path = dir.file("trajectory.tum");
  ape.format = io::TrajectoryFormat::kTum;
  ape.align = eval::AlignmentMode::kSim3;
  const eval::EvalResult ate = eval::evaluate(ape);
  EXPECT_GE(ate.stats.n, 41u);
  EXPECT_LT(ate.stats.rmse, 1.0);
}

TEST(System, KittiMonocularInitialisesEarlyAndTracksEveryLaterFrame) {
  expect_kitti_monocular_tracks_every_frame_after_an_early_start(true);
}

// Threaded, frames as fast as they load: at 12 m/s a monocular map needs every keyframe that
// tracking asks for. Before offline playback waited for a busy mapper (wait_for_mapping), 3 of 5
// such runs on a loaded machine lost the map at frames 9, 28 and 47.
TEST(System, KittiMonocularThreadedOfflineRunTracksEveryLaterFrame) {
  expect_kitti_monocular_tracks_every_frame_after_an_early_start(false);
}

// Ten black frames cut KITTI 06 in two. The monocular map started after them has a scale of its
// own and nothing merges it, so its frames must not share trajectory.tum with the older map's
// (session 31's five unmerged maps gave 58 m of Sim3 ATE in one file).
TEST(System, MonocularMapNeverMergedIsWrittenToItsOwnFile) {
  test::TempDir dir;
  RunConfig config = kitti06_mono_config(dir.file("out"), true);
  config.dataset_path = test::copy_kitti_subset(dir.file("data"), 51);
  const cv::Mat black = cv::Mat::zeros(
      cv::imread(config.dataset_path + "/image_0/000000.png", cv::IMREAD_GRAYSCALE).size(),
      CV_8UC1);
  for (int i = 20; i < 30; ++i)
    cv::imwrite(fmt::format("{}/image_0/{:06d}.png", config.dataset_path, i), black);
  const RunResult result = run_sequence(config);
  ASSERT_EQ(result.maps, 2);
  ASSERT_EQ(result.own_world_frames.size(), 1u);
  const auto [map_id, frames] = *result.own_world_frames.begin();
  const std::string own_file = fmt::format("{}/trajectory_map{}.tum", config.out_dir, map_id);
  const Trajectory own = io::read_tum_trajectory(own_file);
  EXPECT_EQ(own.size(), frames);
  EXPECT_GE(frames, 10u);
  const Trajectory main = io::read_tum_trajectory(config.out_dir + "/trajectory.tum");
  EXPECT_EQ(main.size(), result.frames_tracked);
  const nlohmann::json run =
      nlohmann::json::parse(test::read_text_file(config.out_dir + "/run.json"));
  EXPECT_EQ(main.size() + own.size() + run["untracked_stamps"].size(), 51u);
  EXPECT_EQ(run["maps_in_own_world"][0]["map"], map_id);
  EXPECT_EQ(run["maps_in_own_world"][0]["frames"], frames);
  // The two files split the run in time: one holds frames before the black ones, one after.
  EXPECT_TRUE(own.stamps.back() < main.stamps.front() || main.stamps.back() < own.stamps.front());
}

// KITTI 06 played to frame 50, then frames 3-10 again ("kidnapped" back 47 frames, about 40
// keyframes). The 30 most recent keyframes do not see that place; loop closing's keyframe
// database does, so the first replayed frame relocalises in the same map, and each replayed
// frame lands where its original was estimated.
TEST(System, MonocularFrameKidnappedToAnOldPlaceRelocalisesThroughPlaceRecognition) {
  test::TempDir dir;
  RunConfig config = kitti06_mono_config(dir.file("out"), true);
  config.dataset_path = test::copy_kitti_subset(dir.file("data"), 51);
  std::ofstream listing(config.dataset_path + "/times.txt", std::ios::app);
  std::vector<double> replayed_stamps;
  for (int k = 0; k < 8; ++k) {
    std::filesystem::copy_file(fmt::format("{}/image_0/{:06d}.png", config.dataset_path, 3 + k),
                               fmt::format("{}/image_0/{:06d}.png", config.dataset_path, 51 + k));
    replayed_stamps.push_back(100.0 + 0.1 * k);
    listing << fmt::format("{:.6e}\n", replayed_stamps.back());
  }
  listing.close();
  const RunResult result = run_sequence(config);
  const nlohmann::json run =
      nlohmann::json::parse(test::read_text_file(config.out_dir + "/run.json"));
  EXPECT_EQ(result.maps, 1);
  EXPECT_GE(run["relocalizations"].get<int>(), 1);
  const nlohmann::json timing =
      nlohmann::json::parse(test::read_text_file(config.out_dir + "/timing.json"));
  EXPECT_GE(timing["relocalization_ms"]["n"].get<int>(), run["relocalizations"].get<int>());
  EXPECT_GT(timing["relocalization_ms"]["max"].get<double>(), 0.0);
  const Trajectory& t = result.trajectory;
  const auto position_at = [&](double stamp) -> std::optional<Vec3> {
    for (std::size_t i = 0; i < t.size(); ++i)
      if (std::abs(t.stamps[i] - stamp) < 1e-6) return t.poses[i].translation();
    return std::nullopt;
  };
  std::vector<double> original;
  std::ifstream times(config.dataset_path + "/times.txt");
  for (double stamp = 0.0; times >> stamp;) original.push_back(stamp);
  const std::optional<Vec3> p3 = position_at(original[3]), p10 = position_at(original[10]);
  ASSERT_TRUE(p3 && p10);
  const double span = (*p10 - *p3).norm();
  for (int k = 0; k < 8; ++k) {
    const std::optional<Vec3> replayed = position_at(replayed_stamps[static_cast<std::size_t>(k)]);
    const std::optional<Vec3> first = position_at(original[static_cast<std::size_t>(3 + k)]);
    ASSERT_TRUE(replayed && first) << "frame " << 51 + k;
    EXPECT_LT((*replayed - *first).norm(), 0.05 * span) << "frame " << 51 + k;
  }
}

TEST(System, StereoTracksThroughTheOnsetOfATurn) {
  // city-loop frames 185-229: straight driving, then at frame 200 the car enters a corner and
  // turns 2 degrees per frame at once. The motion model then predicts a view 25 px off; without
  // the reference-keyframe fallback this segment had a 0.72 m error on one frame (RMSE 0.13 m).
  test::TempDir dir;
  test::render_city_loop(dir, 45, 185);

  const RunResult result = run_sequence(test::rendered_kitti_run(dir));
  EXPECT_EQ(result.frames_tracked, 45u);
  EXPECT_EQ(result.maps, 1);

  eval::EvalSettings rpe;
  rpe.metric = eval::Metric::kRpe;
  rpe.reference_path = dir.file("data/poses/00.txt");
  rpe.estimate_path = dir.file("out/trajectory.kitti");
  rpe.format = io::TrajectoryFormat::kKitti;
  const eval::EvalResult errors = eval::evaluate(rpe);
  EXPECT_LT(errors.stats.max, 0.1);    // measured 0.028 m
  EXPECT_LT(errors.stats.rmse, 0.02);  // measured 0.011 m
}

// ORB-SLAM3's Camera.newWidth / newHeight: the same drive at half the size in each direction
// tracks every frame with the scaled camera, and run.json says what was resized.
TEST(System, ResizedImagesAreTrackedWithTheScaledCamera) {
  test::TempDir dir;
  test::render_city_loop(dir, 60);
  const auto ate_of = [&](const std::string& out) {
    eval::EvalSettings ape;
    ape.reference_path = dir.file("data/poses/00.txt");
    ape.estimate_path = dir.file(out + "/trajectory.kitti");
    ape.format = io::TrajectoryFormat::kKitti;
    ape.align = eval::AlignmentMode::kSe3;
    return eval::evaluate(ape).stats.rmse;
  };
  RunConfig config = test::rendered_kitti_run(dir);
  config.out_dir = dir.file("full");
  ASSERT_EQ(run_sequence(config).frames_tracked, 60u);
  const Settings full = load_settings(config.settings_path);
  test::write_text_file(dir.file("half.yaml"),
                        test::read_text_file(config.settings_path) +
                            fmt::format("Camera.newWidth: {}\nCamera.newHeight: {}\n",
                                        full.camera.width / 2, full.camera.height / 2));
  config.settings_path = dir.file("half.yaml");
  config.out_dir = dir.file("half");
  const RunResult half = run_sequence(config);
  EXPECT_EQ(half.frames_tracked, 60u);
  const double ate_full = ate_of("full"), ate_half = ate_of("half");
  std::printf("city-loop 0-59 stereo ATE: %.4f m full size, %.4f m half size\n", ate_full,
              ate_half);
  EXPECT_LT(ate_half, 0.1);
  EXPECT_LT(ate_half, 4.0 * ate_full);
  const nlohmann::json run = nlohmann::json::parse(test::read_text_file(dir.file("half/run.json")));
  EXPECT_EQ(run.at("image_size"), nlohmann::json({full.camera.width / 2, full.camera.height / 2}));
  EXPECT_EQ(run.at("resized_from"), nlohmann::json({full.camera.width, full.camera.height}));
  const nlohmann::json unresized =
      nlohmann::json::parse(test::read_text_file(dir.file("full/run.json")));
  EXPECT_TRUE(unresized.at("resized_from").is_null());
}

struct TurnRun {
  int frames_tracked = 0;
  int weak_motion_model_frames = 0;
  double rotation_error_deg = 0.0;  // of the motion from the first frame to the last
};

// room frames 195-239, deterministic stereo: the first 90-degree turn, whose rotation speeds up
// from 0.7 to 9 degrees per frame within 10 frames, so the constant-velocity guess misses the
// view by up to ~10 px, and slows down again.
TurnRun track_first_room_turn(float motion_model_radius) {
  test::TempDir dir;
  const sim::Scene scene = test::render_scene(dir, "room", 1, 195);
  const Settings settings = load_settings(dir.file("data/settings.yaml"));
  SystemOptions options;
  options.deterministic = true;
  options.seed = 1;
  options.tracker.motion_model_radius = motion_model_radius;
  System system(settings, settings.camera, settings.stereo, options);
  std::vector<SE3> truth;
  for (int k = 0; k < 45; ++k) {
    const sim::StereoFrame frame = sim::render_frame(scene, k);
    truth.push_back(frame.T_world_left);
    system.process(frame.time, frame.left, frame.right);
  }
  system.shutdown();
  const Trajectory estimate = system.frame_trajectory();
  TurnRun run;
  run.frames_tracked = static_cast<int>(estimate.size());
  run.weak_motion_model_frames = system.tracker().weak_motion_model_frames();
  if (estimate.size() == truth.size()) {
    const SO3 true_motion = truth.front().so3().inverse() * truth.back().so3();
    const SO3 motion = estimate.poses.front().so3().inverse() * estimate.poses.back().so3();
    run.rotation_error_deg = (true_motion.inverse() * motion).angle() * 180.0 / M_PI;
  }
  std::printf(
      "radius %.0f px: %d frames tracked, weak motion model on %d, rotation error %.3f deg\n",
      motion_model_radius, run.frames_tracked, run.weak_motion_model_frames,
      run.rotation_error_deg);
  return run;
}

// The default window keeps the motion model's support through the turn; ORB-SLAM3's 7 px stereo
// window does not (measured: 0 and 5 weak frames). On this fresh map both end with a similar
// rotation error (0.55 and 0.43 deg): in the whole sequence the turn's frames meet the map of
// the room seen before, and there the weak frames' poses cost 3.7 cm of ATE against 1.5 cm.
TEST(System, StereoMotionModelKeepsItsSupportThroughAFastTurn) {
  const TurnRun wide = track_first_room_turn(tracking::TrackerOptions{}.motion_model_radius);
  EXPECT_EQ(wide.frames_tracked, 45);
  EXPECT_LE(wide.weak_motion_model_frames, 1);
  EXPECT_LT(wide.rotation_error_deg, 1.0);
  const TurnRun narrow = track_first_room_turn(7.0f);
  EXPECT_EQ(narrow.frames_tracked, 45);
  EXPECT_GE(narrow.weak_motion_model_frames, 3);
}

}  // namespace
}  // namespace sbaslam
