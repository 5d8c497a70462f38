// Map reuse through `run --save-map` and `--load-map`: localising in a saved map without changing
// it (ORB-SLAM3's localization mode), mapping on from one, and the errors a user can meet.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "helper/expect_error.h"
#include "helper/fixture_runs.h"
#include "helper/rendered_run.h"
#include "helper/temp_dir.h"
#include "sbaslam/io/trajectory_io.h"
#include "sbaslam/runner.h"

namespace sbaslam {
namespace {

RunConfig kitti06_mono(const std::string& out) {
  return test::kitti06_mono_config(out, true);
}

std::optional<Vec3> position_at(const Trajectory& t, double stamp) {
  for (std::size_t i = 0; i < t.size(); ++i)
    if (std::abs(t.stamps[i] - stamp) < 1e-6) return t.poses[i].translation();
  return std::nullopt;
}

double path_length(const Trajectory& t) {
  double length = 0.0;
  for (std::size_t i = 1; i < t.size(); ++i)
    length += (t.poses[i].translation() - t.poses[i - 1].translation()).norm();
  return length;
}

nlohmann::json run_json(const RunConfig& config) {
  return nlohmann::json::parse(test::read_text_file(config.out_dir + "/run.json"));
}

// KITTI 06 mapped over its first 31 frames, then all 51 played in the saved map: each mapped
// frame is placed where the mapping run put it (the same world and scale); the 20 frames beyond
// the map are tracked as far as the map's points reach, and the map gains nothing.
TEST(SystemMapFile, MonocularLocalizationOnlyTracksInTheSavedMapAndAddsNothing) {
  test::TempDir dir;
  RunConfig mapping = kitti06_mono(dir.file("mapping"));
  mapping.max_frames = 31;
  mapping.save_map = dir.file("k06.map");
  const RunResult made = run_sequence(mapping);
  ASSERT_EQ(made.frames_tracked, 31u);
  EXPECT_EQ(made.saved_keyframes, made.keyframes);

  RunConfig localising = kitti06_mono(dir.file("localising"));
  localising.load_map = mapping.save_map;
  localising.localization_only = true;
  const RunResult result = run_sequence(localising);
  EXPECT_EQ(result.status, "ok");
  EXPECT_GE(result.frames_tracked, 41u);  // measured: 47 of 51
  EXPECT_EQ(result.maps, 0);
  EXPECT_EQ(result.loaded_keyframes, made.keyframes);
  EXPECT_EQ(result.keyframes, made.keyframes);
  EXPECT_EQ(result.map_points, made.map_points);
  const double span = path_length(made.trajectory);
  for (std::size_t i = 0; i < made.trajectory.size(); ++i) {
    const std::optional<Vec3> p = position_at(result.trajectory, made.trajectory.stamps[i]);
    ASSERT_TRUE(p) << "frame " << i;
    // Measured over all 51 frames mapped: at most 0.017 % of the path.
    EXPECT_LT((*p - made.trajectory.poses[i].translation()).norm(), 0.005 * span) << "frame " << i;
  }
  const nlohmann::json run = run_json(localising);
  EXPECT_GE(run["relocalizations"].get<int>(), 1);
  EXPECT_EQ(run["map_file"]["loaded"], mapping.save_map.value());
  EXPECT_TRUE(run["map_file"]["localization_only"].get<bool>());
  EXPECT_EQ(run["map_file"]["loaded_keyframes"].get<std::size_t>(), made.keyframes);
  EXPECT_GT(run["map_file"]["load_ms"].get<double>(), 0.0);
  EXPECT_GT(run_json(mapping)["map_file"]["save_ms"].get<double>(), 0.0);
  EXPECT_NE(run["trajectory_frame"].get<std::string>().find("loaded map"), std::string::npos);

  // Deterministic from a loaded map too.
  localising.out_dir = dir.file("again");
  run_sequence(localising);
  EXPECT_EQ(test::read_text_file(dir.file("again/trajectory.tum")),
            test::read_text_file(dir.file("localising/trajectory.tum")));
}

// A stereo city drive mapped over its first 20 frames; a second run over all 40 starts in that
// map (its first frame relocalises there instead of starting a map of its own) and maps on.
TEST(SystemMapFile, StereoRunStartsInTheLoadedMapAndMapsOn) {
  test::TempDir dir;
  test::render_city_loop(dir, 40);
  RunConfig mapping = test::rendered_kitti_run(dir);
  mapping.out_dir = dir.file("mapping");
  mapping.max_frames = 20;
  mapping.save_map = dir.file("city.map");
  const RunResult made = run_sequence(mapping);
  ASSERT_EQ(made.frames_tracked, 20u);

  RunConfig continuing = test::rendered_kitti_run(dir);
  continuing.out_dir = dir.file("continuing");
  continuing.load_map = mapping.save_map;
  const RunResult result = run_sequence(continuing);
  EXPECT_EQ(result.frames_tracked, 40u);
  EXPECT_EQ(result.maps, 0);  // no map of its own: the loaded one goes on
  EXPECT_GT(result.keyframes, made.keyframes);
  EXPECT_GE(run_json(continuing)["relocalizations"].get<int>(), 1);
  // The loaded map's world: the poses of the first 20 frames are where the mapping run put them.
  for (std::size_t i = 0; i < made.trajectory.size(); ++i) {
    const std::optional<Vec3> p = position_at(result.trajectory, made.trajectory.stamps[i]);
    ASSERT_TRUE(p) << "frame " << i;
    EXPECT_LT((*p - made.trajectory.poses[i].translation()).norm(), 0.05) << "frame " << i;
  }
  // And the new frames follow the true path (the world is the first frame's camera in both).
  const Trajectory truth = io::read_kitti_trajectory(dir.file("data/poses/00.txt"));
  for (std::size_t i = 20; i < 40; ++i)
    EXPECT_LT((result.trajectory.poses[i].translation() - truth.poses[i].translation()).norm(), 0.3)
        << "frame " << i;
}

// Five black frames in the middle of a stereo drive that was mapped whole: in localization mode
// those frames are lost, and the next one relocalises in the map instead of starting a new one.
TEST(SystemMapFile, StereoLocalizationOnlyRelocalisesAfterALossInsteadOfStartingAMap) {
  test::TempDir dir;
  test::render_city_loop(dir, 40);
  RunConfig mapping = test::rendered_kitti_run(dir);
  mapping.out_dir = dir.file("mapping");
  mapping.save_map = dir.file("city.map");
  const RunResult made = run_sequence(mapping);
  ASSERT_EQ(made.frames_tracked, 40u);
  for (int i = 20; i < 25; ++i)
    for (const char* side : {"image_0", "image_1"}) {
      const std::string image = dir.file(fmt::format("data/sequences/00/{}/{:06d}.png", side, i));
      cv::imwrite(image, cv::Mat::zeros(cv::imread(image).size(), CV_8U));
    }

  RunConfig localising = test::rendered_kitti_run(dir);
  localising.out_dir = dir.file("localising");
  localising.load_map = mapping.save_map;
  localising.localization_only = true;
  const RunResult result = run_sequence(localising);
  EXPECT_EQ(result.maps, 0);
  EXPECT_EQ(result.keyframes, made.keyframes);
  EXPECT_EQ(result.frames_tracked, 35u);  // all but the black ones
  const nlohmann::json run = run_json(localising);
  EXPECT_EQ(run["untracked_stamps"].size(), 5u);
  EXPECT_GE(run["relocalizations"].get<int>(), 2);  // the first frame, and the one after the loss
}

// ORB-SLAM3's settings keys name the files as there: the name plus ".osa".
TEST(SystemMapFile, AtlasKeysOfTheSettingsNameTheMapFiles) {
  test::TempDir dir;
  RunConfig mapping = kitti06_mono(dir.file("mapping"));
  mapping.max_frames = 12;
  const std::string settings = test::read_text_file(mapping.settings_path);
  mapping.settings_path = dir.file("save.yaml");
  test::write_text_file(mapping.settings_path,
                        settings + "\nSystem.SaveAtlasToFile: \"" + dir.file("street") + "\"\n");
  const RunResult made = run_sequence(mapping);
  EXPECT_EQ(run_json(mapping)["map_file"]["saved"], dir.file("street.osa"));
  EXPECT_EQ(made.saved_keyframes, made.keyframes);

  RunConfig localising = kitti06_mono(dir.file("localising"));
  localising.max_frames = 12;
  localising.settings_path = dir.file("load.yaml");
  test::write_text_file(localising.settings_path,
                        settings + "\nSystem.LoadAtlasFromFile: \"" + dir.file("street") + "\"\n");
  localising.localization_only = true;
  const RunResult result = run_sequence(localising);
  EXPECT_EQ(result.loaded_keyframes, made.keyframes);
  EXPECT_EQ(result.keyframes, made.keyframes);
  EXPECT_GE(result.frames_tracked, 10u);
}

TEST(SystemMapFile, LocalizationOnlyWithoutAMapFailsSayingWhatItNeeds) {
  test::TempDir dir;
  RunConfig config = kitti06_mono(dir.file("out"));
  config.localization_only = true;
  test::expect_error_naming([&] { run_sequence(config); }, "--localization-only: needs a map");
}

TEST(SystemMapFile, LoadingAMonocularMapIntoAStereoRunFailsNamingTheFile) {
  test::TempDir dir;
  RunConfig mapping = kitti06_mono(dir.file("mapping"));
  mapping.max_frames = 12;
  mapping.save_map = dir.file("mono.map");
  run_sequence(mapping);
  test::render_city_loop(dir, 2);
  RunConfig stereo = test::rendered_kitti_run(dir);
  stereo.load_map = mapping.save_map;
  test::expect_error_naming([&] { run_sequence(stereo); },
                            dir.file("mono.map") + ": the map was made with a monocular camera");
  stereo.load_map = dir.file("missing.map");
  test::expect_error_naming([&] { run_sequence(stereo); }, "missing.map: map file not found");
}

}  // namespace
}  // namespace sbaslam
