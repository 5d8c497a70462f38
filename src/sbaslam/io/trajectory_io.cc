#include "sbaslam/io/trajectory_io.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <vector>

#include "sbaslam/core/error.h"
#include "sbaslam/core/input_file.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::io {
namespace {

// Far enough from 1 that the file cannot hold a rotation (a zero quaternion, another column
// order); close enough to accept the 7-digit quaternions ORB-SLAM writes.
constexpr double kQuaternionNormTolerance = 1e-2;
// KITTI rotations are rounded to ~7 digits; a row far from orthonormal is not a pose.
constexpr double kRotationOrthonormalTolerance = 1e-2;

struct Row {
  std::size_t line = 0;  // 1-based
  std::vector<std::string_view> tokens;
};

bool is_separator(char c, bool comma_separated) {
  return c == ' ' || c == '\t' || c == '\r' || (comma_separated && c == ',');
}

// Splits the text into non-empty, non-comment lines of tokens. CSV lines may also hold spaces
// after the commas (as some EuRoC exports do).
std::vector<Row> split_rows(const std::string& text, bool comma_separated) {
  std::vector<Row> rows;
  std::size_t line_number = 0;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    ++line_number;
    const std::string_view line(text.data() + begin, end - begin);
    begin = end + 1;

    Row row;
    row.line = line_number;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && is_separator(line[i], comma_separated)) ++i;
      const std::size_t start = i;
      while (i < line.size() && !is_separator(line[i], comma_separated)) ++i;
      if (i > start) row.tokens.push_back(line.substr(start, i - start));
    }
    if (row.tokens.empty() || row.tokens.front().front() == '#') continue;
    rows.push_back(std::move(row));
  }
  return rows;
}

double parse_double(std::string_view token, const std::string& path, std::size_t line) {
  double value = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (!token.empty() && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (ec == std::errc::result_out_of_range ||
      (ec == std::errc() && ptr == last && !std::isfinite(value)))
    fail("{}:{}: '{}' is not a finite number", path, line, token);
  if (ec != std::errc() || ptr != last) fail("{}:{}: '{}' is not a number", path, line, token);
  return value;
}

std::int64_t parse_nanoseconds(std::string_view token, const std::string& path, std::size_t line) {
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size())
    fail("{}:{}: timestamp '{}' is not an integer number of nanoseconds", path, line, token);
  return value;
}

std::vector<double> parse_numbers(const Row& row, std::size_t first, std::size_t count,
                                  const std::string& path) {
  std::vector<double> values;
  values.reserve(count);
  for (std::size_t i = first; i < first + count; ++i)
    values.push_back(parse_double(row.tokens[i], path, row.line));
  return values;
}

void require_columns(const Row& row, std::size_t expected, bool allow_more, const std::string& path,
                     const char* layout) {
  const std::size_t n = row.tokens.size();
  if (n < expected || (!allow_more && n != expected))
    fail("{}:{}: {} columns, expected {}{} ({})", path, row.line, n, expected,
         allow_more ? " or more" : "", layout);
}

void require_writable(const Trajectory& traj, const std::string& path) {
  if (traj.stamps.size() != traj.poses.size())
    fail("{}: trajectory has {} stamps but {} poses", path, traj.stamps.size(), traj.poses.size());
}

}  // namespace

TrajectoryFormat parse_trajectory_format(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  fail("unknown trajectory format '{}' (expected tum, kitti or euroc)", name);
}

std::string trajectory_format_name(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kEuroc:
      return "euroc";
  }
  return "unknown";
}

namespace {

// One pose as the file holds it. TUM and EuRoC rows carry a quaternion (validated, not yet
// normalised); KITTI rows carry the rotation matrix as written.
struct PoseRecord {
  double stamp = 0.0;
  Vec3 position = Vec3::Zero();
  bool has_quaternion = false;
  Quat quaternion = Quat::Identity();
  Mat3 rotation = Mat3::Identity();
};

void check_quaternion(const Quat& q, const std::string& path, std::size_t line) {
  const double norm = q.coeffs().norm();
  if (std::abs(norm - 1.0) > kQuaternionNormTolerance)
    fail("{}:{}: quaternion has norm {}, expected 1", path, line, norm);
}

std::vector<PoseRecord> read_tum_records(const std::string& path) {
  std::vector<PoseRecord> records;
  const std::string text = read_input_file(path);  // the rows view into it
  for (const Row& row : split_rows(text, false)) {
    require_columns(row, 8, false, path, "TUM: t x y z qx qy qz qw");
    const auto v = parse_numbers(row, 0, 8, path);
    PoseRecord record;
    record.stamp = v[0];
    record.position = Vec3(v[1], v[2], v[3]);
    record.has_quaternion = true;
    record.quaternion = Quat(v[7], v[4], v[5], v[6]);
    check_quaternion(record.quaternion, path, row.line);
    records.push_back(record);
  }
  return records;
}

std::vector<PoseRecord> read_kitti_records(const std::string& path) {
  std::vector<PoseRecord> records;
  const std::string text = read_input_file(path);  // the rows view into it
  for (const Row& row : split_rows(text, false)) {
    require_columns(row, 12, false, path, "KITTI: row-major 3x4 [R|t]");
    const auto v = parse_numbers(row, 0, 12, path);
    PoseRecord record;
    record.stamp = static_cast<double>(records.size());
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) record.rotation(r, c) = v[static_cast<std::size_t>(4 * r + c)];
      record.position(r) = v[static_cast<std::size_t>(4 * r + 3)];
    }
    const Mat3& R = record.rotation;
    if ((R * R.transpose() - Mat3::Identity()).norm() > kRotationOrthonormalTolerance ||
        R.determinant() <= 0.0)
      fail("{}:{}: the 3x3 part is not a rotation matrix", path, row.line);
    records.push_back(record);
  }
  return records;
}

std::vector<PoseRecord> read_euroc_records(const std::string& path) {
  std::vector<PoseRecord> records;
  const std::string text = read_input_file(path);  // the rows view into it
  for (const Row& row : split_rows(text, true)) {
    require_columns(row, 8, true, path, "EuRoC: t[ns], p xyz, q wxyz, ...");
    const std::int64_t ns = parse_nanoseconds(row.tokens[0], path, row.line);
    const auto v = parse_numbers(row, 1, 7, path);
    PoseRecord record;
    // Divided like evo does (ns / 1e9), so that stamps compare equal with evo's.
    record.stamp = static_cast<double>(ns) / 1e9;
    record.position = Vec3(v[0], v[1], v[2]);
    record.has_quaternion = true;
    record.quaternion = Quat(v[3], v[4], v[5], v[6]);
    check_quaternion(record.quaternion, path, row.line);
    records.push_back(record);
  }
  return records;
}

std::vector<PoseRecord> read_records(const std::string& path, TrajectoryFormat format) {
  std::vector<PoseRecord> records;
  switch (format) {
    case TrajectoryFormat::kTum:
      records = read_tum_records(path);
      break;
    case TrajectoryFormat::kKitti:
      records = read_kitti_records(path);
      break;
    case TrajectoryFormat::kEuroc:
      records = read_euroc_records(path);
      break;
  }
  if (records.empty()) fail("{}: no poses in the file", path);
  return records;
}

// evo's quaternion_matrix (transformations.py): scale q by sqrt(2 / |q|^2) and build the matrix
// from its outer product. Kept term by term so that evaluation matches evo to the last bits.
Mat3 evo_quaternion_matrix(const Quat& quaternion) {
  double q[4] = {quaternion.w(), quaternion.x(), quaternion.y(), quaternion.z()};
  const double n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
  const double scale = std::sqrt(2.0 / n);
  for (double& v : q) v *= scale;
  double o[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) o[r][c] = q[r] * q[c];
  Mat3 R;
  R << 1.0 - o[2][2] - o[3][3], o[1][2] - o[3][0], o[1][3] + o[2][0],  //
      o[1][2] + o[3][0], 1.0 - o[1][1] - o[3][3], o[2][3] - o[1][0],   //
      o[1][3] - o[2][0], o[2][3] + o[1][0], 1.0 - o[1][1] - o[2][2];
  return R;
}

Trajectory to_trajectory(const std::vector<PoseRecord>& records) {
  Trajectory traj;
  traj.stamps.reserve(records.size());
  traj.poses.reserve(records.size());
  for (const PoseRecord& record : records) {
    const SO3 rotation =
        record.has_quaternion ? SO3(record.quaternion) : SO3::from_matrix(record.rotation);
    traj.push_back(record.stamp, SE3(rotation, record.position));
  }
  return traj;
}

}  // namespace

Trajectory read_tum_trajectory(const std::string& path) {
  return to_trajectory(read_records(path, TrajectoryFormat::kTum));
}

Trajectory read_kitti_trajectory(const std::string& path) {
  return to_trajectory(read_records(path, TrajectoryFormat::kKitti));
}

Trajectory read_euroc_groundtruth(const std::string& path) {
  return to_trajectory(read_records(path, TrajectoryFormat::kEuroc));
}

Trajectory read_trajectory(const std::string& path, TrajectoryFormat format) {
  return to_trajectory(read_records(path, format));
}

PoseMatrixSeries read_pose_matrices(const std::string& path, TrajectoryFormat format) {
  PoseMatrixSeries series;
  for (const PoseRecord& record : read_records(path, format)) {
    Mat4 T = Mat4::Identity();
    T.topLeftCorner<3, 3>() =
        record.has_quaternion ? evo_quaternion_matrix(record.quaternion) : record.rotation;
    T.topRightCorner<3, 1>() = record.position;
    series.stamps.push_back(record.stamp);
    series.poses.push_back(T);
  }
  return series;
}

// fmt's "{}" prints the shortest text that reads back as the same double, so files round-trip.
void write_tum_trajectory(const std::string& path, const Trajectory& traj) {
  require_writable(traj, path);
  std::ofstream out = open_output_file(path);
  out << "# timestamp tx ty tz qx qy qz qw\n";
  for (std::size_t i = 0; i < traj.size(); ++i) {
    const Vec3& t = traj.poses[i].translation();
    const Quat& q = traj.poses[i].quaternion();
    out << fmt::format("{} {} {} {} {} {} {} {}\n", traj.stamps[i], t.x(), t.y(), t.z(), q.x(),
                       q.y(), q.z(), q.w());
  }
  close_output_file(out, path);
}

void write_kitti_trajectory(const std::string& path, const Trajectory& traj) {
  require_writable(traj, path);
  std::ofstream out = open_output_file(path);
  for (const SE3& pose : traj.poses) {
    const Mat34 T = pose.matrix3x4();
    out << fmt::format("{} {} {} {} {} {} {} {} {} {} {} {}\n", T(0, 0), T(0, 1), T(0, 2), T(0, 3),
                       T(1, 0), T(1, 1), T(1, 2), T(1, 3), T(2, 0), T(2, 1), T(2, 2), T(2, 3));
  }
  close_output_file(out, path);
}

void write_euroc_trajectory(const std::string& path, const Trajectory& traj) {
  require_writable(traj, path);
  std::ofstream out = open_output_file(path);
  out << "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],"
         "q_RS_z []\n";
  for (std::size_t i = 0; i < traj.size(); ++i) {
    const double stamp_ns = std::round(traj.stamps[i] * 1e9);
    if (!std::isfinite(stamp_ns) || std::abs(stamp_ns) > 9.2e18)
      fail("{}: stamp {} s of pose {} cannot be written in nanoseconds", path, traj.stamps[i], i);
    const Vec3& t = traj.poses[i].translation();
    const Quat& q = traj.poses[i].quaternion();
    out << fmt::format("{},{},{},{},{},{},{},{}\n", static_cast<std::int64_t>(stamp_ns), t.x(),
                       t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
  }
  close_output_file(out, path);
}

void write_trajectory(const std::string& path, const Trajectory& traj, TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return write_tum_trajectory(path, traj);
    case TrajectoryFormat::kKitti:
      return write_kitti_trajectory(path, traj);
    case TrajectoryFormat::kEuroc:
      return write_euroc_trajectory(path, traj);
  }
}

}  // namespace sbaslam::io
