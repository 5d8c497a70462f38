#include "sbaslam/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/camera.h"
#include "sbaslam/core/error.h"
#include "sbaslam/sim/city_scene.h"
#include "sbaslam/sim/procedural_textures.h"
#include "sbaslam/sim/random.h"
#include "sbaslam/sim/room_scene.h"
#include "sbaslam/sim/vehicle_path.h"

namespace sbaslam::sim {
namespace {

// Photographs in a folder, in name order so that the result never depends on the file system.
std::vector<cv::Mat> load_photos(const std::string& dir) {
  if (dir.empty()) return {};
  if (!std::filesystem::is_directory(dir)) fail("{}: texture folder not found", dir);
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg"))
      paths.push_back(entry.path().string());
  }
  if (paths.empty()) fail("{}: no .png or .jpg photographs in the texture folder", dir);
  std::sort(paths.begin(), paths.end());
  std::vector<cv::Mat> photos;
  for (const auto& p : paths) photos.push_back(photo_texture(p));
  return photos;
}

void make_city(Scene& s, bool straight, bool dynamic) {
  const SceneOptions& o = s.options;
  s.layout = DatasetLayout::kKitti;
  // KITTI odometry's rectified grayscale cameras (sequences 00-02).
  s.camera = ViewCamera{718.856, 718.856, 607.1928, 185.2157, 1241, 376}.scaled(o.resolution_scale);
  s.baseline = 0.54;
  s.rate_hz = 10.0;
  s.exposure_time = 0.004;
  s.world = build_city_world(o.seed, load_photos(o.texture_dir));
  auto route = std::make_shared<const Route>(straight ? straight_route() : city_loop_route());
  auto schedule =
      std::make_shared<const DrivingSchedule>(*route, DrivingStyle{}, 0.0, kCityEgoLane);
  s.route_length = route->length();
  s.left_camera_pose = [route, schedule](double t) {
    return vehicle_camera_pose(*route, *schedule, 0.0, kCityEgoLane, kCityCameraHeight, t);
  };
  s.light_level = [](double) { return 1.0; };
  if (straight) {
    s.max_frames =
        static_cast<int>(std::floor(schedule->time_for(route->length() - 0.01) * s.rate_hz));
    s.default_frames = std::min(100, s.max_frames);
  } else {
    // One lap plus the first 180 m again, so the drive ends on a revisited street.
    s.default_frames =
        static_cast<int>(std::floor(schedule->time_for(route->length() + 180.0) * s.rate_hz)) + 1;
  }
  if (dynamic) {
    if (o.dynamic_objects < 0) fail("--dynamic-objects: must be >= 0, got {}", o.dynamic_objects);
    add_city_traffic(
        s.world, route, [schedule](double t) { return schedule->distance_at(t); },
        o.dynamic_objects, mix_seed(o.seed, 0x7aff1c));
  }
}

void make_room(Scene& s) {
  const SceneOptions& o = s.options;
  s.layout = DatasetLayout::kEuroc;
  // EuRoC cam0 intrinsics, rendered without distortion (as after rectification).
  s.camera = ViewCamera{458.654, 457.296, 367.215, 248.375, 752, 480}.scaled(o.resolution_scale);
  s.baseline = 0.11;
  s.rate_hz = 20.0;
  s.exposure_time = 0.006;
  s.world = build_room_world(o.seed, load_photos(o.texture_dir));
  // Camera looking along the body's x axis, cam0 on the left of the body.
  Mat3 R_BS;
  R_BS << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  s.T_body_left = SE3(SO3::from_matrix(R_BS), Vec3(0.05, 0.5 * s.baseline, -0.02));
  const std::uint64_t seed = o.seed;
  const SE3 T_BS = s.T_body_left;
  s.left_camera_pose = [seed, T_BS](double t) { return room_body_pose(t, seed) * T_BS; };
  s.light_level = room_light_level;
  s.default_frames = 600;
}

// The pinhole canvas covering every ray of the fisheye image of `camera` (same focal length), and
// where each fisheye pixel samples it.
FisheyeWarp make_fisheye_warp(const ViewCamera& camera) {
  const PinholeCamera lens({camera.fx, camera.fy, camera.cx, camera.cy}, kFisheyeLens);
  FisheyeWarp warp;
  warp.map_x.create(camera.height, camera.width, CV_32F);
  warp.map_y.create(camera.height, camera.width, CV_32F);
  double min_x = std::numeric_limits<double>::infinity(), min_y = min_x;
  double max_x = -min_x, max_y = -min_x;
  for (int v = 0; v < camera.height; ++v)
    for (int u = 0; u < camera.width; ++u) {
      const Vec2 p = lens.undistort(Vec2(u, v));
      warp.map_x.at<float>(v, u) = static_cast<float>(p.x());
      warp.map_y.at<float>(v, u) = static_cast<float>(p.y());
      min_x = std::min(min_x, p.x());
      max_x = std::max(max_x, p.x());
      min_y = std::min(min_y, p.y());
      max_y = std::max(max_y, p.y());
    }
  // One pixel of margin for bilinear sampling at the extremes.
  const double left = std::floor(min_x) - 1.0, top = std::floor(min_y) - 1.0;
  warp.canvas = ViewCamera{camera.fx,
                           camera.fy,
                           camera.cx - left,
                           camera.cy - top,
                           static_cast<int>(std::ceil(max_x - left)) + 2,
                           static_cast<int>(std::ceil(max_y - top)) + 2};
  warp.map_x -= left;
  warp.map_y -= top;
  return warp;
}

// A view through the fisheye: rendered on the pinhole canvas, then resampled; depth and labels by
// the nearest canvas pixel, which keeps them exact.
void render_fisheye_view(const Scene& scene, const SE3& T_world_camera, double time,
                         ViewLayers& layers) {
  const FisheyeWarp& warp = *scene.fisheye;
  ViewLayers canvas;
  render_view(scene.world, warp.canvas, T_world_camera, time, canvas);
  cv::remap(canvas.radiance, layers.radiance, warp.map_x, warp.map_y, cv::INTER_LINEAR);
  cv::remap(canvas.depth, layers.depth, warp.map_x, warp.map_y, cv::INTER_NEAREST);
  cv::remap(canvas.label, layers.label, warp.map_x, warp.map_y, cv::INTER_NEAREST);
}

void render_camera_view(const Scene& scene, const SE3& T_world_camera, double time,
                        ViewLayers& layers) {
  if (scene.fisheye) {
    render_fisheye_view(scene, T_world_camera, time, layers);
  } else {
    render_view(scene.world, scene.camera, T_world_camera, time, layers);
  }
}

}  // namespace

std::vector<std::string> scene_names() {
  return {"city-loop", "city-dynamic", "room", "straight"};
}

Scene make_scene(const SceneOptions& options) {
  if (!(options.resolution_scale > 0.05 && options.resolution_scale <= 4.0))
    fail("--resolution-scale: must be in (0.05, 4], got {}", options.resolution_scale);
  Scene s;
  s.options = options;
  if (options.name == "city-loop")
    make_city(s, false, false);
  else if (options.name == "city-dynamic")
    make_city(s, false, true);
  else if (options.name == "straight")
    make_city(s, true, false);
  else if (options.name == "room")
    make_room(s);
  else
    fail("--scene: unknown scene '{}' (known: city-loop, city-dynamic, room, straight)",
         options.name);
  if (options.fisheye) {
    // KITTI's calib.txt can only describe rectified pinhole cameras.
    if (s.layout != DatasetLayout::kEuroc)
      fail(
          "--fisheye: scene '{}' is written in the KITTI layout, which has no fisheye model; "
          "use room",
          options.name);
    s.fisheye = make_fisheye_warp(s.camera);
  }
  return s;
}

SE3 Scene::right_camera_pose(double t) const {
  return left_camera_pose(t) * SE3(SO3(), Vec3(baseline, 0.0, 0.0));
}

double exposure_gain(const Scene& scene, int index) {
  const double t = scene.time_of(index);
  // Auto-exposure compensates only part of a change of light, as real cameras with a bounded
  // exposure time do.
  double gain = std::pow(scene.light_level(t), -0.55);
  if (scene.options.effects.exposure_changes) {
    Random rng(mix_seed(scene.options.seed, 0xe4905e));
    const double p1 = rng.uniform(0, 2 * M_PI), p2 = rng.uniform(0, 2 * M_PI);
    const double drift =
        0.07 * std::sin(2 * M_PI * t / 17.3 + p1) + 0.04 * std::sin(2 * M_PI * t / 5.1 + p2);
    // Steps of the exposure controller every 4 s, held in between.
    const auto period = static_cast<std::uint64_t>(std::floor(t / 4.0));
    const double step =
        0.2 * (Random(mix_seed(scene.options.seed, 0x57e9, period)).uniform() - 0.5);
    gain *= std::exp(drift + step);
  }
  return gain;
}

namespace {

// Image motion, in pixels, of the point seen at the principal point during the exposure.
cv::Vec2d blur_vector(const Scene& scene, double t, double exposure, double depth) {
  const SE3 T_wc = scene.left_camera_pose(t);
  const Vec3 X = T_wc * Vec3(0.0, 0.0, depth > 0.0 ? depth : 30.0);
  const ViewCamera& c = scene.camera;
  auto project = [&](double time) {
    const Vec3 p = scene.left_camera_pose(time).inverse() * X;
    return Vec2(c.fx * p.x() / p.z() + c.cx, c.fy * p.y() / p.z() + c.cy);
  };
  const Vec2 d = project(t + 0.5 * exposure) - project(t - 0.5 * exposure);
  return {d.x(), d.y()};
}

}  // namespace

StereoFrame render_frame(const Scene& scene, int index) {
  StereoFrame f;
  f.index = index;
  f.time = scene.time_of(index);
  f.T_world_left = scene.left_camera_pose(f.time);
  ViewLayers left, right;
  render_camera_view(scene, f.T_world_left, f.time, left);
  render_camera_view(scene, scene.right_camera_pose(f.time), f.time, right);
  const double light = scene.light_level(f.time);
  const double gain = exposure_gain(scene, index) * light;
  const ImageEffects& fx = scene.options.effects;
  cv::Vec2d blur(0.0, 0.0);
  if (fx.motion_blur) {
    const int cx =
        std::clamp(static_cast<int>(std::lround(scene.camera.cx)), 0, scene.camera.width - 1);
    const int cy =
        std::clamp(static_cast<int>(std::lround(scene.camera.cy)), 0, scene.camera.height - 1);
    const double exposure = scene.exposure_time * exposure_gain(scene, index);
    blur = blur_vector(scene, f.time, exposure, left.depth.at<float>(cy, cx));
  }
  const std::uint64_t seed = scene.options.seed;
  const auto k = static_cast<std::uint64_t>(index);
  f.left = expose_image(left.radiance, gain, blur, fx, mix_seed(seed, k, 1));
  f.right = expose_image(right.radiance, gain, blur, fx, mix_seed(seed, k, 2));
  f.depth = left.depth;
  f.label = left.label;
  return f;
}

nlohmann::json Scene::describe() const {
  const ImageEffects& e = options.effects;
  nlohmann::json j;
  j["scene"] = options.name;
  j["seed"] = options.seed;
  j["layout"] = layout == DatasetLayout::kKitti ? "kitti" : "euroc";
  j["dynamic_objects"] = static_cast<int>(world.objects.size());
  j["resolution_scale"] = options.resolution_scale;
  j["texture_dir"] = options.texture_dir;
  j["camera"] = {{"fx", camera.fx},
                 {"fy", camera.fy},
                 {"cx", camera.cx},
                 {"cy", camera.cy},
                 {"width", camera.width},
                 {"height", camera.height},
                 {"distortion", fisheye ? "kannala-brandt" : "none"},
                 {"pixel_convention", "pixel (x, y) samples the ray through (x, y)"}};
  if (fisheye)
    j["camera"]["kannala_brandt"] = {kFisheyeLens.k1, kFisheyeLens.k2, kFisheyeLens.k3,
                                     kFisheyeLens.k4};
  j["stereo"] = {{"baseline_m", baseline}, {"right_camera", "left pose * translation (b, 0, 0)"}};
  j["rate_hz"] = rate_hz;
  j["exposure_time_s"] = exposure_time;
  j["default_frames"] = default_frames;
  j["max_frames"] = max_frames;
  j["route_length_m"] = route_length;
  j["effects"] = {{"sensor_noise", e.sensor_noise},
                  {"read_noise", e.read_noise},
                  {"shot_noise", e.shot_noise},
                  {"motion_blur", e.motion_blur},
                  {"exposure_changes", e.exposure_changes},
                  {"vignetting", e.vignetting},
                  {"vignetting_strength", e.vignetting_strength}};
  j["depth"] = {
      {"encoding", "16-bit PNG"},
      {"scale", 256.0},
      {"meaning",
       "metres = value / 256 (z in the left camera); 0 = no depth (sky, or beyond 255.99 m)"}};
  j["semantic"] = {{"encoding", "8-bit PNG, Cityscapes label ids"},
                   {"labels",
                    {{"road", 7},
                     {"sidewalk", 8},
                     {"parking", 9},
                     {"rail track", 10},
                     {"building", 11},
                     {"fence", 13},
                     {"bridge", 15},
                     {"pole", 17},
                     {"polegroup", 18},
                     {"traffic light", 19},
                     {"traffic sign", 20},
                     {"vegetation", 21},
                     {"terrain", 22},
                     {"sky", 23},
                     {"person", 24},
                     {"rider", 25},
                     {"car", 26},
                     {"truck", 27},
                     {"bus", 28}}}};
  if (layout == DatasetLayout::kEuroc)
    j["semantic"]["indoor_mapping"] = "walls and ceiling 11, floor 8, boxes and furniture 13";
  std::vector<double> T;
  const Mat4 M = T_body_left.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T.push_back(M(r, c));
  j["T_body_left"] = T;
  j["world"] = {{"static_quads", world.quads.size()},
                {"textures", world.textures.size()},
                {"moving_objects", world.objects.size()}};
  nlohmann::json kinds = nlohmann::json::array();
  for (const auto& obj : world.objects) kinds.push_back(obj.kind);
  j["world"]["moving_object_kinds"] = kinds;
  return j;
}

}  // namespace sbaslam::sim
