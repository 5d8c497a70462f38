// Saliency.depth "velodyne": KITTI scans next to the images, moved into the left camera by
// calib.txt's Tr. The simulator writes such scans from its rendered depth, so every projected
// sample must land on the pixel it was read from, with that pixel's depth.

#include "sbaslam/saliency/velodyne_depth.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "helper/expect_error.h"
#include "helper/rendered_run.h"
#include "helper/temp_dir.h"
#include "sbaslam/io/image_io.h"
#include "sbaslam/io/kitti_reader.h"
#include "sbaslam/runner.h"
#include "sbaslam/sim/dataset_writer.h"
#include "sbaslam/sim/scene.h"
#include "sbaslam/sim/velodyne_sampler.h"

namespace sbaslam::saliency {
namespace {

struct RenderedScan {
  sim::Scene scene;
  sim::StereoFrame frame;
};

RenderedScan write_city_dynamic_with_scans(const test::TempDir& dir, int frames) {
  sim::SceneOptions options;
  options.name = "city-dynamic";
  RenderedScan out{sim::make_scene(options), {}};
  sim::WriteOptions write;
  write.frames = frames;
  write.velodyne = true;
  sim::write_dataset(out.scene, dir.file("data"), write);
  out.frame = sim::render_frame(out.scene, 0);
  return out;
}

TEST(VelodyneDepth, RenderedScanProjectsOntoTheRenderedDepth) {
  test::TempDir dir;
  const RenderedScan r = write_city_dynamic_with_scans(dir, 1);
  const auto calibration = io::read_kitti_calibration_rows(dir.file("data/sequences/00/calib.txt"));
  EXPECT_TRUE(SE3::from_matrix(calibration.at("Tr"))
                  .matrix()
                  .isApprox(sim::camera_from_velodyne().matrix(), 1e-12));

  const sim::ViewCamera& c = r.scene.camera;
  VelodyneDepth velodyne({c.fx, c.fy, c.cx, c.cy}, cv::Size(c.width, c.height));
  const std::vector<DepthSample> samples =
      velodyne.samples_for(dir.file("data/sequences/00/image_0/000000.png"));
  ASSERT_GE(samples.size(), 10000u);
  int off = 0;
  for (const DepthSample& s : samples) {
    const int u = static_cast<int>(std::lround(s.u)), v = static_cast<int>(std::lround(s.v));
    const float truth = r.frame.depth.at<float>(v, u);
    // float32 coordinates: a few 1e-4 px and 1e-6 relative.
    off += std::abs(s.u - u) > 1e-3f || std::abs(s.v - v) > 1e-3f ||
           std::abs(s.depth - truth) > 1e-5f * truth;
  }
  EXPECT_EQ(off, 0);
}

TEST(VelodyneDepth, MissingScanOrCalibrationRowIsAnErrorNamingTheFile) {
  test::TempDir dir;
  const RenderedScan r = write_city_dynamic_with_scans(dir, 1);
  const sim::ViewCamera& c = r.scene.camera;
  VelodyneDepth velodyne({c.fx, c.fy, c.cx, c.cy}, cv::Size(c.width, c.height));
  const std::string message = test::error_message(
      [&] { velodyne.samples_for(dir.file("data/sequences/00/image_0/000007.png")); });
  EXPECT_NE(message.find("velodyne/000007.bin: velodyne scan not found"), std::string::npos)
      << message;

  // The same sequence with a calib.txt that has no Tr row.
  const std::string calib = dir.file("data/sequences/00/calib.txt");
  std::string rows = test::read_text_file(calib);
  rows = rows.substr(0, rows.find("Tr:"));
  std::ofstream(calib) << rows;
  VelodyneDepth fresh({c.fx, c.fy, c.cx, c.cy}, cv::Size(c.width, c.height));
  const std::string no_tr = test::error_message(
      [&] { fresh.samples_for(dir.file("data/sequences/00/image_0/000000.png")); });
  EXPECT_NE(no_tr.find("calib.txt: no Tr row"), std::string::npos) << no_tr;
}

// A salient run of the rendered sequence with D from its scans; without the scans it stops with
// the missing file's name.
TEST(VelodyneDepth, SalientRunTakesDepthFromTheScans) {
  test::TempDir dir;
  write_city_dynamic_with_scans(dir, 5);
  const std::string settings_path = dir.file("data/settings.yaml");
  std::string settings = test::read_text_file(settings_path);
  const std::string key = "Saliency.depth: \"auto\"";
  ASSERT_NE(settings.find(key), std::string::npos);
  settings.replace(settings.find(key), key.size(), "Saliency.depth: \"velodyne\"");
  std::ofstream(settings_path) << settings;

  RunConfig config = test::rendered_kitti_run(dir);
  config.saliency = "model";
  const RunResult result = run_sequence(config);
  EXPECT_EQ(result.frames_tracked, 5u);
  EXPECT_NE(test::read_text_file(dir.file("out/run.json")).find("\"depth\": \"velodyne\""),
            std::string::npos);

  std::filesystem::remove_all(dir.file("data/sequences/00/velodyne"));
  const std::string message = test::error_message([&] { run_sequence(config); });
  EXPECT_NE(message.find("velodyne/000000.bin: velodyne scan not found"), std::string::npos)
      << message;
}

TEST(VelodyneDepth, PointsBehindOrOutsideTheCameraDrop) {
  const PinholeIntrinsics k{100.0, 100.0, 50.0, 40.0};
  std::vector<io::VelodynePoint> scan(4);
  scan[0].xyz = Eigen::Vector3f(10.0f, 0.0f, 0.0f);   // ahead: the image centre at 10 m
  scan[1].xyz = Eigen::Vector3f(-10.0f, 0.0f, 0.0f);  // behind
  scan[2].xyz = Eigen::Vector3f(10.0f, 30.0f, 0.0f);  // far to the left: outside
  scan[3].xyz = Eigen::Vector3f(0.5f, 0.0f, 0.0f);    // nearer than 1 m
  const std::vector<DepthSample> samples =
      project_scan(scan, sim::camera_from_velodyne(), k, cv::Size(100, 80));
  ASSERT_EQ(samples.size(), 1u);
  EXPECT_NEAR(samples[0].depth, 10.0 - 0.27, 1e-5);
  EXPECT_NEAR(samples[0].u, 50.0, 1e-4);
  EXPECT_NEAR(samples[0].v, 40.0 + 100.0 * -0.08 / 9.73, 1e-3);
}

}  // namespace
}  // namespace sbaslam::saliency
