#include "sbaslam/io/tum_reader.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <tuple>

#include "sbaslam/core/error.h"
#include "sbaslam/io/image_io.h"
#include "sbaslam/io/text_lines.h"
#include "sbaslam/io/trajectory_io.h"

namespace sbaslam::io {
namespace fs = std::filesystem;

std::vector<TumListEntry> read_tum_image_list(const std::string& list_path) {
  const fs::path folder = fs::path(list_path).parent_path();
  std::vector<TumListEntry> entries;
  for (const TextLine& line : read_data_lines(list_path)) {
    const auto fields = split_fields(line.text, " \t");
    if (fields.size() != 2) fail("{}:{}: expected 'timestamp filename'", list_path, line.number);
    TumListEntry entry;
    entry.stamp = parse_number(fields[0], list_path, line.number, "timestamp");
    entry.path = (folder / fields[1]).string();
    if (!fs::is_regular_file(entry.path))
      fail("{}:{}: image file {} not found", list_path, line.number, entry.path);
    if (!entries.empty() && entry.stamp <= entries.back().stamp)
      fail("{}:{}: timestamp {:.6f} {} the previous one ({:.6f})", list_path, line.number,
           entry.stamp, entry.stamp == entries.back().stamp ? "repeats" : "is earlier than",
           entries.back().stamp);
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) fail("{}: no images listed (empty sequence)", list_path);
  return entries;
}

std::vector<std::pair<std::size_t, std::size_t>> associate_stamps(const std::vector<double>& a,
                                                                  const std::vector<double>& b,
                                                                  double max_gap) {
  // Candidates within the gap, found with a sliding window over the sorted b.
  std::vector<std::tuple<double, std::size_t, std::size_t>> candidates;
  std::size_t first = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    while (first < b.size() && b[first] <= a[i] - max_gap) ++first;
    for (std::size_t j = first; j < b.size() && b[j] < a[i] + max_gap; ++j)
      if (std::abs(a[i] - b[j]) < max_gap) candidates.emplace_back(std::abs(a[i] - b[j]), i, j);
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> used_a(a.size(), false), used_b(b.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& [gap, i, j] : candidates) {
    if (used_a[i] || used_b[j]) continue;
    used_a[i] = used_b[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

TumReader::TumReader(const std::string& dataset_dir, const DatasetOptions& options) {
  const fs::path dir(dataset_dir);
  const std::string rgb_list = (dir / "rgb.txt").string();
  const auto rgb = read_tum_image_list(rgb_list);
  const std::string depth_list = (dir / "depth.txt").string();
  has_depth_ = options.load_depth && fs::is_regular_file(depth_list);
  if (!has_depth_) {
    for (const auto& entry : rgb) frames_.push_back({entry.stamp, entry.stamp, entry.path, {}});
  } else {
    const auto depth = read_tum_image_list(depth_list);
    std::vector<double> rgb_stamps, depth_stamps;
    for (const auto& entry : rgb) rgb_stamps.push_back(entry.stamp);
    for (const auto& entry : depth) depth_stamps.push_back(entry.stamp);
    for (const auto& [i, j] : associate_stamps(rgb_stamps, depth_stamps, kMaxAssociationGap))
      frames_.push_back({rgb[i].stamp, depth[j].stamp, rgb[i].path, depth[j].path});
    if (frames_.empty())
      fail("{}: no rgb frame has a depth frame within {} s in {}", rgb_list, kMaxAssociationGap,
           depth_list);
    if (frames_.size() < rgb.size())
      spdlog::info("{}: {} of {} rgb frames have no depth frame within {} s; they are skipped",
                   rgb_list, rgb.size() - frames_.size(), rgb.size(), kMaxAssociationGap);
  }
  ground_truth_path_ = (dir / "groundtruth.txt").string();
}

FrameData TumReader::load(std::size_t i) const {
  const Frame& f = frames_.at(i);
  FrameData frame;
  frame.index = i;
  frame.timestamp = f.rgb_stamp;
  frame.left_path = f.rgb_path;
  frame.left = read_gray_image(f.rgb_path);
  if (has_depth_) {
    frame.depth = read_depth_image(f.depth_path);
    if (frame.depth.size() != frame.left.size())
      fail("{}: depth image is {}x{}, the rgb image {}x{}", f.depth_path, frame.depth.cols,
           frame.depth.rows, frame.left.cols, frame.left.rows);
  }
  return frame;
}

std::optional<Trajectory> TumReader::ground_truth() const {
  if (!fs::is_regular_file(ground_truth_path_)) return std::nullopt;
  return read_tum_trajectory(ground_truth_path_);
}

}  // namespace sbaslam::io
