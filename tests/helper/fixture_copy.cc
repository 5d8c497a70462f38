#include "helper/fixture_copy.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "helper/temp_dir.h"

namespace sbaslam::test {
namespace fs = std::filesystem;

namespace {

// The first `n` data lines of a listing, with its comment lines kept.
std::vector<std::string> head_lines(const std::string& path, std::size_t n, std::string* comments) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<std::string> lines;
  std::string line;
  while (lines.size() < n && std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') {
      *comments += line + "\n";
      continue;
    }
    lines.push_back(line);
  }
  return lines;
}

void copy_euroc_camera(const fs::path& src, const fs::path& dst, std::size_t n) {
  fs::create_directories(dst / "data");
  fs::copy_file(src / "sensor.yaml", dst / "sensor.yaml");
  std::string csv;
  for (const std::string& line : head_lines((src / "data.csv").string(), n, &csv)) {
    csv += line + "\n";
    const std::string name = line.substr(line.find(',') + 1);
    fs::copy_file(src / "data" / name, dst / "data" / name);
  }
  write_text_file((dst / "data.csv").string(), csv);
}

}  // namespace

std::string shared_data_dir() {
  return std::string(SBASLAM_SHARED_DIR) + "/data";
}
std::string euroc_fixture_dir() {
  return shared_data_dir() + "/euroc_v101_micro";
}
std::string kitti_fixture_sequence_dir() {
  return shared_data_dir() + "/kitti06_first51/sequences/06";
}

std::string copy_euroc_subset(const std::string& dst_root, std::size_t n, bool with_cam1) {
  const fs::path src = fs::path(euroc_fixture_dir()) / "mav0";
  const fs::path dst = fs::path(dst_root) / "euroc" / "mav0";
  copy_euroc_camera(src / "cam0", dst / "cam0", n);
  if (with_cam1) copy_euroc_camera(src / "cam1", dst / "cam1", n);
  return dst.parent_path().string();
}

std::string copy_kitti_subset(const std::string& dst_root, std::size_t n) {
  const fs::path src = kitti_fixture_sequence_dir();
  const fs::path dst = fs::path(dst_root) / "kitti" / "sequences" / "06";
  fs::create_directories(dst / "image_0");
  fs::copy_file(src / "calib.txt", dst / "calib.txt");
  std::string ignored, times, poses;
  for (const std::string& line : head_lines((src / "times.txt").string(), n, &ignored))
    times += line + "\n";
  write_text_file((dst / "times.txt").string(), times);
  const fs::path poses_src = src.parent_path().parent_path() / "poses" / "06.txt";
  for (const std::string& line : head_lines(poses_src.string(), n, &ignored)) poses += line + "\n";
  write_text_file((dst.parent_path().parent_path() / "poses" / "06.txt").string(), poses);
  for (std::size_t i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", i);
    fs::copy_file(src / "image_0" / name, dst / "image_0" / name);
  }
  return dst.string();
}

void write_euroc_groundtruth_csv(const std::string& tum_path, const std::string& euroc_root) {
  std::ifstream in(tum_path);
  if (!in) throw std::runtime_error("cannot read " + tum_path);
  std::ostringstream csv;
  csv << "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
         "q_RS_z [],v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],b_w_RS_S_x [rad s^-1],"
         "b_w_RS_S_y [rad s^-1],b_w_RS_S_z [rad s^-1],b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],"
         "b_a_RS_S_z [m s^-2]\n";
  csv.precision(17);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z, qx, qy, qz, qw;
    fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    csv << static_cast<long long>(std::llround(t * 1e9)) << "," << x << "," << y << "," << z << ","
        << qw << "," << qx << "," << qy << "," << qz << ",0,0,0,0,0,0,0,0,0\n";
  }
  write_text_file(
      (fs::path(euroc_root) / "mav0" / "state_groundtruth_estimate0" / "data.csv").string(),
      csv.str());
}

void truncate_file(const std::string& path, std::size_t bytes) {
  fs::resize_file(path, bytes);
}

}  // namespace sbaslam::test
