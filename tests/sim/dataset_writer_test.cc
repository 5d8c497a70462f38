// The simulator's output read back by the project's own dataset readers, byte-identical output
// for any thread count, and the one-line errors of `sba-slam simulate`.

#include "sbaslam/sim/dataset_writer.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "sbaslam/core/error.h"
#include "sbaslam/io/euroc_reader.h"
#include "sbaslam/io/kitti_reader.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::sim {
namespace {
namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("sbaslam_sim_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

Scene small_scene(const std::string& name) {
  SceneOptions o;
  o.name = name;
  o.seed = 11;
  o.resolution_scale = 0.2;
  o.dynamic_objects = 4;
  return make_scene(o);
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SimDatasetWriter, FirstFrameStartsASegmentOfTheMotion) {
  SceneOptions o = small_scene("city-loop").options;
  o.first_frame = 30;
  const Scene scene = make_scene(o);
  TempDir dir;
  WriteOptions options;
  options.frames = 3;
  write_dataset(scene, dir.path().string(), options);
  io::KittiReader reader((dir.path() / "sequences" / "00").string());
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_NEAR(reader.timestamp(0), 3.0, 1e-9);
  const Trajectory gt = io::read_kitti_trajectory((dir.path() / "poses" / "00.txt").string());
  ASSERT_EQ(gt.size(), 3u);
  // The ground truth starts at the identity and moves as the scene does from frame 30 on.
  EXPECT_LT(gt.poses[0].translation().norm(), 1e-9);
  const SE3 expected = scene.left_camera_pose(3.0).inverse() * scene.left_camera_pose(3.2);
  EXPECT_LT((gt.poses[2].translation() - expected.translation()).norm(), 1e-6);

  o.first_frame = -1;
  EXPECT_THROW(write_dataset(make_scene(o), dir.path().string(), options), Error);
}

TEST(SimDatasetWriter, AStopRequestEndsWritingAfterTheFramesStartedAndReturnsTheirCount) {
  const Scene scene = small_scene("straight");
  TempDir dir;
  WriteOptions options;
  options.frames = 8;
  options.threads = 1;
  int asked = 0;
  options.stop_requested = [&asked] { return ++asked > 3; };
  EXPECT_EQ(write_dataset(scene, dir.path().string(), options), 3);
  const fs::path images = dir.path() / "sequences" / "00" / "image_0";
  EXPECT_TRUE(fs::exists(images / "000002.png"));
  EXPECT_FALSE(fs::exists(images / "000003.png"));
  // An incomplete dataset gets no ground truth, so no reader takes it for a whole one.
  EXPECT_FALSE(fs::exists(dir.path() / "poses" / "00.txt"));
}

TEST(SimDatasetWriter, KittiReaderReadsCityOutput) {
  const Scene scene = small_scene("straight");
  TempDir dir;
  WriteOptions options;
  options.frames = 4;
  ASSERT_EQ(write_dataset(scene, dir.path().string(), options), 4);

  io::KittiReader reader((dir.path() / "sequences" / "00").string());
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_TRUE(reader.has_right());
  EXPECT_NEAR(reader.baseline(), scene.baseline, 1e-9);
  EXPECT_NEAR(reader.timestamp(3), 0.3, 1e-9);
  const auto calib = reader.calibration();
  ASSERT_TRUE(calib.has_value());
  EXPECT_NEAR(calib->camera.intrinsics.fx, scene.camera.fx, 1e-9);
  EXPECT_NEAR(calib->camera.intrinsics.cy, scene.camera.cy, 1e-9);
  EXPECT_EQ(calib->camera.width, scene.camera.width);

  const auto gt = reader.ground_truth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 4u);
  EXPECT_LT((gt->poses[0].matrix() - Mat4::Identity()).norm(), 1e-9);
  const SE3 expected = scene.left_camera_pose(0.0).inverse() * scene.left_camera_pose(0.3);
  EXPECT_LT((gt->poses[3].matrix() - expected.matrix()).norm(), 1e-6);
  EXPECT_GT(gt->poses[3].translation().z(), 1.5);  // driving forward along the camera's z

  const io::FrameData f = reader.load(2);
  const StereoFrame rendered = render_frame(scene, 2);
  EXPECT_EQ(cv::norm(f.left, rendered.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(f.right, rendered.right, cv::NORM_INF), 0.0);

  const cv::Mat depth =
      cv::imread((dir.path() / "sequences/00/depth/000002.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16U);
  const cv::Mat labels =
      cv::imread((dir.path() / "sequences/00/semantic/000002.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(labels.type(), CV_8U);
  EXPECT_EQ(cv::norm(labels, rendered.label, cv::NORM_INF), 0.0);
  for (int y = 0; y < depth.rows; y += 5)
    for (int x = 0; x < depth.cols; x += 5) {
      const float z = rendered.depth.at<float>(y, x);
      const double decoded = depth.at<std::uint16_t>(y, x) / kDepthPngScale;
      if (z > 0.0f && z < 250.0f) {
        EXPECT_NEAR(decoded, z, 0.5 / kDepthPngScale + 1e-6);
      } else if (z == 0.0f) {
        EXPECT_EQ(depth.at<std::uint16_t>(y, x), 0);
      }
    }

  const nlohmann::json j = nlohmann::json::parse(read_bytes(dir.path() / "scene.json"));
  EXPECT_EQ(j.at("scene"), "straight");
  EXPECT_EQ(j.at("seed"), 11);
  EXPECT_EQ(j.at("frames"), 4);
  const Settings settings = load_settings((dir.path() / "settings.yaml").string());
  EXPECT_NEAR(settings.camera.intrinsics.fx, scene.camera.fx, 1e-9);
  EXPECT_NEAR(settings.stereo.baseline, scene.baseline, 1e-9);
}

TEST(SimDatasetWriter, EurocReaderReadsRoomOutput) {
  const Scene scene = small_scene("room");
  TempDir dir;
  WriteOptions options;
  options.frames = 3;
  write_dataset(scene, dir.path().string(), options);

  io::EurocReader reader(dir.path().string());
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_TRUE(reader.has_right());
  EXPECT_EQ(reader.timestamp_ns(1), euroc_timestamp_ns(scene, 1));
  const auto calib = reader.calibration();
  ASSERT_TRUE(calib.has_value());
  EXPECT_LT((calib->T_body_cam0.matrix() - scene.T_body_left.matrix()).norm(), 1e-9);
  ASSERT_TRUE(calib->stereo.has_value());
  EXPECT_NEAR(calib->stereo->baseline, scene.baseline, 1e-6);

  const auto gt = reader.ground_truth();
  ASSERT_TRUE(gt.has_value());
  // 200 Hz body poses over the 0.1 s span of the images.
  EXPECT_EQ(gt->size(), 21u);
  for (std::size_t i = 0; i < gt->size(); i += 10) {
    const double t = gt->stamps[i] - gt->stamps[0];
    const SE3 T_world_cam = gt->poses[i] * scene.T_body_left;
    EXPECT_LT((T_world_cam.translation() - scene.left_camera_pose(t).translation()).norm(), 1e-6);
    EXPECT_LT((T_world_cam.so3().inverse() * scene.left_camera_pose(t).so3()).angle(), 1e-6);
  }
  const io::FrameData f = reader.load(1);
  EXPECT_EQ(f.left.cols, scene.camera.width);
  EXPECT_EQ(f.left.rows, scene.camera.height);
  for (const char* stream : {"depth0", "semantic0"})
    EXPECT_TRUE(fs::is_regular_file(dir.path() / "mav0" / stream / "data" /
                                    (std::to_string(euroc_timestamp_ns(scene, 2)) + ".png")));
}

// `--sensor rgbd` runs read the depth images beside the images through the same readers.
TEST(SimDatasetWriter, ReadersReturnTheDepthImagesOfAnRgbdSequence) {
  TempDir kitti, euroc;
  WriteOptions options;
  options.frames = 3;
  write_dataset(small_scene("straight"), kitti.path().string(), options);
  write_dataset(small_scene("room"), euroc.path().string(), options);
  io::DatasetOptions rgbd;
  rgbd.load_right = false;
  rgbd.load_depth = true;

  const io::KittiReader city((kitti.path() / "sequences" / "00").string(), rgbd);
  ASSERT_TRUE(city.has_depth());
  const io::FrameData f = city.load(1);
  const cv::Mat stored =
      cv::imread((kitti.path() / "sequences/00/depth/000001.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(f.depth.type(), CV_16U);
  EXPECT_EQ(cv::norm(f.depth, stored, cv::NORM_INF), 0.0);

  const io::EurocReader room(euroc.path().string(), rgbd);
  ASSERT_TRUE(room.has_depth());
  const io::FrameData g = room.load(2);
  const cv::Mat stored_room =
      cv::imread((euroc.path() / "mav0/depth0/data" /
                  (std::to_string(euroc_timestamp_ns(small_scene("room"), 2)) + ".png"))
                     .string(),
                 cv::IMREAD_UNCHANGED);
  EXPECT_EQ(cv::norm(g.depth, stored_room, cv::NORM_INF), 0.0);
  // Rectified stereo images are not the ones the depth is registered to.
  EXPECT_FALSE(io::EurocReader(euroc.path().string()).has_depth());
  io::DatasetOptions no_depth = rgbd;
  no_depth.load_depth = false;
  EXPECT_FALSE(io::KittiReader((kitti.path() / "sequences" / "00").string(), no_depth).has_depth());

  fs::remove(kitti.path() / "sequences/00/depth/000002.png");
  try {
    io::KittiReader broken((kitti.path() / "sequences" / "00").string(), rgbd);
    FAIL() << "a missing depth image was not reported";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no depth image '000002.png'"), std::string::npos)
        << e.what();
  }
}

TEST(SimDatasetWriter, OutputDoesNotDependOnThreadCount) {
  const Scene scene = small_scene("city-dynamic");
  TempDir one, two;
  WriteOptions options;
  options.frames = 3;
  options.threads = 1;
  write_dataset(scene, one.path().string(), options);
  options.threads = 2;
  write_dataset(scene, two.path().string(), options);
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(one.path())) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), one.path());
    ASSERT_TRUE(fs::exists(two.path() / rel)) << rel;
    EXPECT_EQ(read_bytes(entry.path()), read_bytes(two.path() / rel)) << rel;
    ++compared;
  }
  EXPECT_GE(compared, 3 * 4 + 4);
}

TEST(SimDatasetWriter, RejectsBadRequests) {
  SceneOptions o;
  o.name = "nowhere";
  EXPECT_THROW(make_scene(o), Error);
  const Scene scene = small_scene("straight");
  TempDir dir;
  WriteOptions options;
  options.frames = -1;
  EXPECT_THROW(write_dataset(scene, dir.path().string(), options), Error);
  options.frames = scene.max_frames + 1;
  EXPECT_THROW(write_dataset(scene, dir.path().string(), options), Error);
  // A folder below a regular file cannot be created.
  std::ofstream(dir.path() / "file") << "x";
  options.frames = 1;
  EXPECT_THROW(write_dataset(scene, (dir.path() / "file" / "out").string(), options), Error);
}

TEST(SimDatasetWriter, CliReportsErrorsOnOneLine) {
  TempDir dir;
  const fs::path err = dir.path() / "stderr.txt";
  auto run = [&](const std::string& args) {
    const std::string cmd = std::string(SBASLAM_CLI) + " simulate " + args + " 2> " + err.string();
    const int status = std::system(cmd.c_str());
    return std::make_pair(WEXITSTATUS(status), read_bytes(err));
  };
  auto [code, text] = run("--scene mars --frames 2 --out " + (dir.path() / "a").string());
  EXPECT_EQ(code, 1);
  EXPECT_NE(text.find("sba-slam: error: --scene: unknown scene 'mars'"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  std::tie(code, text) = run("--scene room --frames 0 --out " + (dir.path() / "b").string());
  EXPECT_EQ(code, 1);
  EXPECT_NE(text.find("--frames: must be positive"), std::string::npos) << text;
}

}  // namespace
}  // namespace sbaslam::sim
