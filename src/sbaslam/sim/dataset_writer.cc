#include "sbaslam/sim/dataset_writer.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <thread>
#include <vector>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/core/trajectory.h"
#include "sbaslam/io/trajectory_io.h"
#include "sbaslam/io/velodyne_scan.h"
#include "sbaslam/sim/velodyne_sampler.h"

namespace sbaslam::sim {
namespace fs = std::filesystem;

namespace {

constexpr long long kEurocStartNs = 1'600'000'000'000'000'000LL;
constexpr double kEurocGroundTruthRate = 200.0;

void make_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    fail("{}: cannot create the folder ({})", dir.string(), ec.message());
}

void write_png(const fs::path& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image, {cv::IMWRITE_PNG_COMPRESSION, 3});
  } catch (const cv::Exception& e) {
    fail("{}: cannot write the image ({})", path.string(), e.err);
  }
  if (!ok) fail("{}: cannot write the image", path.string());
}

// A calib.txt row: the name, then the 3x4 matrix row by row.
std::string matrix_row(const char* name, const Mat34& M) {
  std::string row = name;
  row += ":";
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) row += fmt::format(" {:.12e}", M(r, c));
  return row + "\n";
}

// Rectified 3x4 projection of a camera offset by `x` metres along the baseline.
std::string projection_row(const char* name, const ViewCamera& c, double x) {
  Mat34 P;
  P << c.fx, 0.0, c.cx, -c.fx * x, 0.0, c.fy, c.cy, 0.0, 0.0, 0.0, 1.0, 0.0;
  return matrix_row(name, P);
}

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void prepare(int frames) = 0;
  virtual void write(const StereoFrame& frame) = 0;
  virtual void finish(int frames) = 0;
};

class KittiSink : public FrameSink {
 public:
  KittiSink(const Scene& scene, const fs::path& root, bool velodyne)
      : scene_(scene), root_(root), seq_(root / "sequences" / "00"), velodyne_(velodyne) {}

  void prepare(int frames) override {
    for (const char* d : {"image_0", "image_1", "depth", "semantic"}) make_dir(seq_ / d);
    if (velodyne_) make_dir(seq_ / "velodyne");
    make_dir(root_ / "poses");
    const fs::path calib = seq_ / "calib.txt";
    std::ofstream out = open_output_file(calib.string());
    out << projection_row("P0", scene_.camera, 0.0)
        << projection_row("P1", scene_.camera, scene_.baseline)
        << projection_row("P2", scene_.camera, 0.0)
        << projection_row("P3", scene_.camera, scene_.baseline)
        << matrix_row("Tr", camera_from_velodyne().matrix3x4());
    close_output_file(out, calib.string());
    const fs::path times = seq_ / "times.txt";
    std::ofstream t = open_output_file(times.string());
    for (int i = 0; i < frames; ++i) t << fmt::format("{:e}\n", scene_.time_of(i));
    close_output_file(t, times.string());
  }

  void write(const StereoFrame& f) override {
    const std::string name = fmt::format("{:06d}.png", f.index);
    write_png(seq_ / "image_0" / name, f.left);
    write_png(seq_ / "image_1" / name, f.right);
    write_png(seq_ / "depth" / name, encode_depth(f.depth));
    write_png(seq_ / "semantic" / name, f.label);
    if (velodyne_)
      io::write_velodyne_scan((seq_ / "velodyne" / fmt::format("{:06d}.bin", f.index)).string(),
                              sample_velodyne_scan(f.depth, scene_.camera));
  }

  void finish(int frames) override {
    // Left camera poses relative to the first one, as KITTI gives them.
    const SE3 T_first_world = scene_.left_camera_pose(scene_.time_of(0)).inverse();
    Trajectory traj;
    for (int i = 0; i < frames; ++i)
      traj.push_back(scene_.time_of(i), T_first_world * scene_.left_camera_pose(scene_.time_of(i)));
    io::write_kitti_trajectory((root_ / "poses" / "00.txt").string(), traj);
  }

 private:
  const Scene& scene_;
  fs::path root_, seq_;
  bool velodyne_;
};

std::string matrix_yaml(const Mat4& T) {
  std::string s = "  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      s += fmt::format("{:.15g}{}", T(r, c), r == 3 && c == 3 ? "]\n" : ", ");
  return s;
}

class EurocSink : public FrameSink {
 public:
  EurocSink(const Scene& scene, const fs::path& root) : scene_(scene), mav_(root / "mav0") {}

  void prepare(int frames) override {
    const char* streams[] = {"cam0", "cam1", "depth0", "semantic0"};
    for (const char* d : streams) {
      make_dir(mav_ / d / "data");
      const fs::path csv = mav_ / d / "data.csv";
      std::ofstream out = open_output_file(csv.string());
      out << "#timestamp [ns],filename\n";
      for (int i = 0; i < frames; ++i) {
        const long long ns = euroc_timestamp_ns(scene_, i);
        out << ns << "," << ns << ".png\n";
      }
      close_output_file(out, csv.string());
    }
    write_sensor_yaml("cam0", scene_.T_body_left, "left camera of the simulated stereo rig");
    write_sensor_yaml("cam1", scene_.T_body_left * SE3(SO3(), Vec3(scene_.baseline, 0, 0)),
                      "right camera of the simulated stereo rig");
    const fs::path body = mav_ / "body.yaml";
    std::ofstream b = open_output_file(body.string());
    b << "%YAML:1.0\ncomment: 'Simulated MAV body frame: x forward, y left, z up.'\n";
    close_output_file(b, body.string());
  }

  void write(const StereoFrame& f) override {
    const std::string name = fmt::format("{}.png", euroc_timestamp_ns(scene_, f.index));
    write_png(mav_ / "cam0" / "data" / name, f.left);
    write_png(mav_ / "cam1" / "data" / name, f.right);
    write_png(mav_ / "depth0" / "data" / name, encode_depth(f.depth));
    write_png(mav_ / "semantic0" / "data" / name, f.label);
  }

  void finish(int frames) override {
    // Body ground truth at 200 Hz over the span of the images, with velocities by central
    // differences and zero IMU biases, in the columns of EuRoC's state_groundtruth_estimate0.
    const fs::path dir = mav_ / "state_groundtruth_estimate0";
    make_dir(dir);
    const fs::path csv = dir / "data.csv";
    std::ofstream out = open_output_file(csv.string());
    out << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
           "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad "
           "s^-1], "
           "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m "
           "s^-2], "
           "b_a_RS_S_z [m s^-2]\n";
    const SE3 T_left_body = scene_.T_body_left.inverse();
    auto body = [&](double t) { return scene_.left_camera_pose(t) * T_left_body; };
    const long long step_ns = static_cast<long long>(std::llround(1e9 / kEurocGroundTruthRate));
    const long long end_ns = static_cast<long long>(std::llround(scene_.time_of(frames - 1) * 1e9));
    const long long start_ns = static_cast<long long>(std::llround(scene_.time_of(0) * 1e9));
    for (long long ns = start_ns; ns <= end_ns; ns += step_ns) {
      const double t = static_cast<double>(ns) * 1e-9;
      const SE3 T = body(t);
      const Vec3 v = (body(t + 1e-3).translation() - body(t - 1e-3).translation()) / 2e-3;
      const Quat& q = T.quaternion();
      const Vec3& p = T.translation();
      out << fmt::format(
          "{},{:.9f},{:.9f},{:.9f},{:.12f},{:.12f},{:.12f},{:.12f},{:.9f},{:.9f},{:.9f},"
          "0,0,0,0,0,0\n",
          kEurocStartNs + ns, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z());
    }
    close_output_file(out, csv.string());
  }

 private:
  void write_sensor_yaml(const char* cam, const SE3& T_BS, const char* comment) {
    const ViewCamera& c = scene_.camera;
    const fs::path path = mav_ / cam / "sensor.yaml";
    std::ofstream out = open_output_file(path.string());
    out << "%YAML:1.0\n"
        << "sensor_type: camera\n"
        << "comment: " << comment
        << (scene_.fisheye ? " (rendered through a Kannala-Brandt fisheye lens)\n"
                           : " (rendered without distortion)\n")
        << "T_BS:\n"
        << matrix_yaml(T_BS.matrix()) << fmt::format("rate_hz: {}\n", scene_.rate_hz)
        << fmt::format("resolution: [{}, {}]\n", c.width, c.height) << "camera_model: pinhole\n"
        << fmt::format("intrinsics: [{:.10g}, {:.10g}, {:.10g}, {:.10g}]\n", c.fx, c.fy, c.cx, c.cy)
        << (scene_.fisheye
                ? fmt::format("distortion_model: equidistant\n"
                              "distortion_coefficients: [{:.10g}, {:.10g}, {:.10g}, {:.10g}]\n",
                              kFisheyeLens.k1, kFisheyeLens.k2, kFisheyeLens.k3, kFisheyeLens.k4)
                : "distortion_model: radial-tangential\n"
                  "distortion_coefficients: [0.0, 0.0, 0.0, 0.0]\n");
    close_output_file(out, path.string());
  }

  const Scene& scene_;
  fs::path mav_;
};

// Renders frames [0, frames) on `threads` workers and returns how many were written. Each frame
// depends only on its index, so the files are the same for any number of threads.
int render_all(const Scene& scene, FrameSink& sink, int frames, const WriteOptions& options) {
  std::atomic<int> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&] {
    while (!stop) {
      if (options.stop_requested && options.stop_requested()) {
        stop = true;
        return;
      }
      const int i = next++;
      if (i >= frames) return;
      try {
        sink.write(render_frame(scene, i));
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        stop = true;
        return;
      }
      ++done;
    }
  };
  const int n = std::max(1, std::min(options.threads, frames));
  std::vector<std::thread> pool;
  for (int k = 0; k < n; ++k) pool.emplace_back(worker);
  while (done < frames && !stop) {
    if (options.progress) options.progress(done, frames);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (options.progress) options.progress(done, frames);
  return done;
}

}  // namespace

cv::Mat encode_depth(const cv::Mat& depth_m) {
  cv::Mat out(depth_m.size(), CV_16U);
  for (int y = 0; y < depth_m.rows; ++y) {
    const float* d = depth_m.ptr<float>(y);
    std::uint16_t* o = out.ptr<std::uint16_t>(y);
    for (int x = 0; x < depth_m.cols; ++x) {
      const double v = std::round(d[x] * kDepthPngScale);
      o[x] = (d[x] > 0.0f && v <= 65535.0) ? static_cast<std::uint16_t>(v) : 0;
    }
  }
  return out;
}

long long euroc_timestamp_ns(const Scene& scene, int frame) {
  return kEurocStartNs + std::llround(scene.time_of(frame) * 1e9);
}

Settings scene_settings(const Scene& scene) {
  Settings s;
  const ViewCamera& c = scene.camera;
  s.camera.intrinsics = {c.fx, c.fy, c.cx, c.cy};
  s.camera.width = c.width;
  s.camera.height = c.height;
  s.camera.fps = scene.rate_hz;
  s.camera.rgb = false;
  s.stereo.enabled = true;
  s.stereo.baseline = scene.baseline;
  if (scene.fisheye) {
    // As ORB-SLAM3's TUM-VI files: two fisheye cameras and their pose, to be rectified.
    s.camera.model = CameraModel::kKannalaBrandt8;
    s.camera.fisheye = kFisheyeLens;
    s.stereo.right = s.camera;
    s.stereo.T_c1_c2 = SE3(SO3(), Vec3(scene.baseline, 0.0, 0.0));
  } else {
    s.stereo.bf = scene.baseline * c.fx;
  }
  const bool kitti = scene.layout == DatasetLayout::kKitti;
  // ORB-SLAM3's values for its KITTI and EuRoC stereo examples.
  s.stereo.th_depth = kitti ? 35.0 : 60.0;
  // For `--sensor rgbd` on the depth images written beside the images.
  s.rgbd.depth_map_factor = kDepthPngScale;
  s.orb.n_features = kitti ? 2000 : 1200;
  s.system.seed = scene.options.seed;
  return s;
}

int write_dataset(const Scene& scene, const std::string& out_dir, const WriteOptions& options) {
  const int frames = options.frames == 0 ? scene.default_frames : options.frames;
  if (frames <= 0) fail("--frames: must be positive, got {}", frames);
  if (scene.options.first_frame < 0)
    fail("--first-frame: must be non-negative, got {}", scene.options.first_frame);
  if (scene.max_frames > 0 && scene.options.first_frame + frames > scene.max_frames)
    fail("--frames: scene '{}' has at most {} frames, got {} from frame {}", scene.options.name,
         scene.max_frames, frames, scene.options.first_frame);
  if (options.velodyne && scene.layout != DatasetLayout::kKitti)
    fail("--velodyne: scene '{}' is written in the EuRoC layout; velodyne scans are KITTI's",
         scene.options.name);
  const fs::path root(out_dir);
  make_dir(root);
  const fs::path json_path = root / "scene.json";
  {
    nlohmann::json j = scene.describe();
    j["frames"] = frames;
    write_output_file(json_path.string(), j.dump(2) + "\n");
  }
  save_settings(scene_settings(scene), (root / "settings.yaml").string());
  std::unique_ptr<FrameSink> sink;
  if (scene.layout == DatasetLayout::kKitti)
    sink = std::make_unique<KittiSink>(scene, root, options.velodyne);
  else
    sink = std::make_unique<EurocSink>(scene, root);
  sink->prepare(frames);
  const int written = render_all(scene, *sink, frames, options);
  if (written < frames) return written;
  sink->finish(frames);
  return frames;
}

}  // namespace sbaslam::sim
