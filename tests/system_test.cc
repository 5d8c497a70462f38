// End-to-end stereo SLAM on the real EuRoC fixture: the drone stands still in these 95 frames, so
// the estimate must not drift, and deterministic mode must reproduce itself bit for bit.

#include "sbaslam/system.h"

#include <gtest/gtest.h>

#include "helper/temp_dir.h"
#include "sbaslam/eval/evaluator.h"
#include "sbaslam/runner.h"

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

}  // namespace
}  // namespace sbaslam
