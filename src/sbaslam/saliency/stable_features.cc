#include "sbaslam/saliency/stable_features.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include "sbaslam/core/error.h"
#include "sbaslam/core/output_file.h"
#include "sbaslam/io/text_lines.h"

namespace sbaslam::saliency {
namespace {

constexpr const char* kHeader = "timestamp,image,x,y,octave,point_id,observations,mean_error_px";
constexpr std::size_t kColumns = 8;

double mean_normalised_error(const PointTrack& track) {
  double sum = 0.0;
  for (const PointObservation& o : track.observations) sum += o.error_px / o.level_sigma;
  return sum / static_cast<double>(track.observations.size());
}

double mean_error_px(const PointTrack& track) {
  double sum = 0.0;
  for (const PointObservation& o : track.observations) sum += o.error_px;
  return sum / static_cast<double>(track.observations.size());
}

// A non-negative integer field (octave, point id, observation count).
std::size_t parse_count(const std::string& field, const std::string& path, std::size_t line,
                        const char* what) {
  const double value = io::parse_number(field, path, line, what);
  if (value < 0.0 || value != std::floor(value) ||
      value > static_cast<double>(std::numeric_limits<int>::max()))
    fail("{}:{}: {} '{}' is not a non-negative integer", path, line, what, field);
  return static_cast<std::size_t>(value);
}

StableFeature parse_row(const io::TextLine& line, const std::string& path) {
  const std::vector<std::string> f = io::split_fields(line.text, ",");
  if (f.size() != kColumns)
    fail("{}:{}: expected {} comma-separated fields ({}), got {}", path, line.number, kColumns,
         kHeader, f.size());
  StableFeature row;
  row.timestamp = io::parse_number(f[0], path, line.number, "timestamp");
  row.image = f[1];
  if (row.image.empty()) fail("{}:{}: empty image name", path, line.number);
  row.x = static_cast<float>(io::parse_number(f[2], path, line.number, "x"));
  row.y = static_cast<float>(io::parse_number(f[3], path, line.number, "y"));
  if (row.x < 0.0f || row.y < 0.0f)
    fail("{}:{}: negative pixel position ({}, {})", path, line.number, f[2], f[3]);
  row.octave = static_cast<int>(parse_count(f[4], path, line.number, "octave"));
  row.point_id = parse_count(f[5], path, line.number, "point_id");
  row.observations = static_cast<int>(parse_count(f[6], path, line.number, "observations"));
  row.mean_error_px = io::parse_number(f[7], path, line.number, "mean_error_px");
  return row;
}

}  // namespace

bool is_stable(const PointTrack& track, const StabilityGate& gate) {
  if (track.observations.empty() ||
      static_cast<int>(track.observations.size()) < gate.min_observations)
    return false;
  const double e = mean_normalised_error(track);
  return std::isfinite(e) && e * e < gate.max_chi2;
}

std::vector<StableFeature> select_stable_features(const std::vector<PointTrack>& tracks,
                                                  const StabilityGate& gate) {
  std::vector<StableFeature> rows;
  for (const PointTrack& track : tracks) {
    if (!is_stable(track, gate)) continue;
    const double error = mean_error_px(track);
    const int count = static_cast<int>(track.observations.size());
    for (const PointObservation& o : track.observations)
      rows.push_back({o.timestamp, o.image, o.x, o.y, o.octave, track.point_id, count, error});
  }
  std::stable_sort(rows.begin(), rows.end(), [](const StableFeature& a, const StableFeature& b) {
    return a.timestamp != b.timestamp ? a.timestamp < b.timestamp : a.point_id < b.point_id;
  });
  return rows;
}

void write_stable_features_csv(const std::string& path, const std::vector<StableFeature>& rows) {
  std::ofstream out = open_output_file(path);
  out << kHeader << '\n';
  for (const StableFeature& r : rows) {
    if (r.image.find(',') != std::string::npos)
      fail("{}: image name '{}' holds a comma, which the csv cannot carry", path, r.image);
    out << fmt::format("{:.9f},{},{:.3f},{:.3f},{},{},{},{:.4f}\n", r.timestamp, r.image, r.x, r.y,
                       r.octave, r.point_id, r.observations, r.mean_error_px);
  }
  close_output_file(out, path);
}

std::vector<StableFeature> read_stable_features_csv(const std::string& path) {
  std::ifstream probe(path);
  if (!probe) fail("{}: cannot read the stable-features csv", path);
  const std::vector<io::TextLine> lines = io::read_data_lines(path);
  if (lines.empty() || lines.front().text != kHeader)
    fail("{}: not a stable-features csv (the first line must be '{}')", path, kHeader);
  std::vector<StableFeature> rows;
  rows.reserve(lines.size() - 1);
  for (std::size_t i = 1; i < lines.size(); ++i) rows.push_back(parse_row(lines[i], path));
  return rows;
}

}  // namespace sbaslam::saliency
