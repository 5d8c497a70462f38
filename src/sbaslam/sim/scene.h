#pragma once
// The simulator's scenes: a world, a stereo rig, its motion and its camera model, under one name
// and one seed. render_frame() is a pure function of the scene and the frame index, so frames can
// be rendered in any order and on any number of threads with identical results.
//
//   city-loop     KITTI-like stereo rig driving about 1.6 km through a city with two loops;
//   city-dynamic  the same streets and drive, with moving cars, trucks, buses and pedestrians;
//   room          EuRoC-like stereo MAV in a textured room: 6-DoF motion, fast turns, dark segment;
//   straight      a short straight drive on a city street, for unit tests.

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sbaslam/core/lie.h"
#include "sbaslam/core/settings.h"
#include "sbaslam/sim/image_effects.h"
#include "sbaslam/sim/renderer.h"
#include "sbaslam/sim/world.h"

namespace sbaslam::sim {

enum class DatasetLayout { kKitti, kEuroc };

struct SceneOptions {
  std::string name = "straight";
  std::uint64_t seed = 1;
  int dynamic_objects = 12;       // city-dynamic only
  double resolution_scale = 1.0;  // < 1 renders smaller images (intrinsics scaled alike)
  ImageEffects effects;
  std::string texture_dir;  // optional photographs replacing facades (city) or walls (room)
  int first_frame = 0;      // frame 0 of the output is this frame of the scene's motion
  bool fisheye = false;     // EuRoC-layout scenes: a Kannala-Brandt fisheye rig (kFisheyeLens)
};

// The fisheye lens of `SceneOptions::fisheye`: near-equidistant, like TUM-VI's, on the scene's
// focal length, so that the image sees wider than the pinhole one (56 degrees off axis at the
// room's corners against 46).
constexpr KannalaBrandtDistortion kFisheyeLens{0.0035, 0.0007, -0.002, 0.0002};

// How a fisheye image is made from a pinhole render: `canvas` is a pinhole view wide enough for
// every ray of the fisheye image, and (map_x, map_y) give each fisheye pixel's place in it.
struct FisheyeWarp {
  ViewCamera canvas;
  cv::Mat map_x, map_y;  // CV_32F, the fisheye image's size
};

// The names make_scene() accepts.
std::vector<std::string> scene_names();

struct Scene {
  SceneOptions options;
  DatasetLayout layout = DatasetLayout::kKitti;
  World world;
  ViewCamera camera;  // left camera; the right one is the same, baseline metres along x
  // With SceneOptions::fisheye: `camera` holds the fisheye's intrinsics, kFisheyeLens its lens.
  std::optional<FisheyeWarp> fisheye;
  double baseline = 0.0;
  double rate_hz = 10.0;
  double exposure_time = 0.004;  // seconds at unit gain; grows with the gain (motion blur)
  int default_frames = 0;
  int max_frames = 0;                           // 0: the motion goes on forever
  std::function<SE3(double)> left_camera_pose;  // T_world_left at time t
  std::function<double(double)> light_level;    // illumination factor at time t
  SE3 T_body_left;            // EuRoC T_BS of cam0 (the body is the MAV); identity for KITTI
  double route_length = 0.0;  // metres, for the record

  // Scene time of output frame `frame` (counted from options.first_frame).
  double time_of(int frame) const { return (options.first_frame + frame) / rate_hz; }
  SE3 right_camera_pose(double t) const;
  // Everything that defines the scene, for scene.json.
  nlohmann::json describe() const;
};

// Builds a scene. Throws sbaslam::Error for an unknown name or invalid options.
Scene make_scene(const SceneOptions& options);

struct StereoFrame {
  int index = 0;
  double time = 0.0;
  SE3 T_world_left;
  cv::Mat left, right;  // CV_8U
  cv::Mat depth;        // CV_32F metres (z in the left camera), 0 = sky / nothing
  cv::Mat label;        // CV_8U Cityscapes ids, left camera
};

StereoFrame render_frame(const Scene& scene, int index);

// Camera gain of a frame (auto-exposure following the light level, with drift and steps when
// exposure changes are on).
double exposure_gain(const Scene& scene, int index);

}  // namespace sbaslam::sim
