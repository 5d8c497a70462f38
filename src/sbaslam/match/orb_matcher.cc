#include "sbaslam/match/orb_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "sbaslam/core/error.h"
#include "sbaslam/match/hamming.h"

namespace sbaslam::match {
namespace {

void check_descriptors(const cv::Mat& d, const char* what) {
  if (!d.empty() && (d.type() != CV_8UC1 || d.cols != kDescriptorBytes || !d.isContinuous()))
    fail("ORB matcher: {} descriptors must be a continuous N x 32 CV_8U matrix", what);
}

struct Nearest {
  int best = -1, best_distance = INT_MAX, best_level = -1;
  int second_distance = INT_MAX, second_level = -1;
  void offer(int index, int distance, int level) {
    if (distance < best_distance) {
      second_distance = best_distance;
      second_level = best_level;
      best_distance = distance;
      best_level = level;
      best = index;
    } else if (distance < second_distance) {
      second_distance = distance;
      second_level = level;
    }
  }
};

// Resolves keypoints claimed by several points (the smallest distance wins), then applies the
// rotation check.
std::vector<Match> keep_unique(std::vector<Match> candidates, std::size_t n_train,
                               const std::vector<ProjectedPoint>& points, const FrameView& frame,
                               const ProjectionOptions& options) {
  std::vector<int> owner(n_train, -1);
  for (std::size_t m = 0; m < candidates.size(); ++m) {
    int& o = owner[candidates[m].train];
    if (o < 0 || candidates[m].distance < candidates[o].distance) o = static_cast<int>(m);
  }
  std::vector<Match> unique;
  for (std::size_t m = 0; m < candidates.size(); ++m)
    if (owner[candidates[m].train] == static_cast<int>(m)) unique.push_back(candidates[m]);
  if (!options.check_orientation) return unique;

  RotationConsistency rotation(options.rotation_bins);
  for (std::size_t m = 0; m < unique.size(); ++m) {
    const float reference = points[unique[m].query].angle;
    if (reference >= 0.0f)
      rotation.add(static_cast<int>(m), reference, frame.keypoints[unique[m].train].angle);
  }
  const std::vector<int> rejected = rotation.inconsistent();
  std::vector<Match> kept;
  for (std::size_t m = 0; m < unique.size(); ++m)
    if (!std::binary_search(rejected.begin(), rejected.end(), static_cast<int>(m)))
      kept.push_back(unique[m]);
  return kept;
}

}  // namespace

RotationConsistency::RotationConsistency(int bins) {
  if (bins < 3) fail("rotation consistency: needs at least 3 bins (got {})", bins);
  bins_.resize(bins);
}

void RotationConsistency::add(int match_id, float reference_angle_deg, float angle_deg) {
  float rotation = reference_angle_deg - angle_deg;
  rotation = std::fmod(rotation, 360.0f);
  if (rotation < 0.0f) rotation += 360.0f;
  const int n = static_cast<int>(bins_.size());
  int bin = static_cast<int>(rotation * static_cast<float>(n) / 360.0f);
  if (bin >= n || bin < 0) bin = 0;  // 360 after rounding, or a NaN angle
  bins_[bin].push_back(match_id);
}

std::vector<int> RotationConsistency::inconsistent() const {
  int top[3] = {-1, -1, -1};
  auto count = [&](int b) { return b < 0 ? 0 : static_cast<int>(bins_[b].size()); };
  for (int b = 0; b < static_cast<int>(bins_.size()); ++b) {
    const int c = count(b);
    if (c > count(top[0])) {
      top[2] = top[1];
      top[1] = top[0];
      top[0] = b;
    } else if (c > count(top[1])) {
      top[2] = top[1];
      top[1] = b;
    } else if (c > count(top[2])) {
      top[2] = b;
    }
  }
  const float tenth = 0.1f * static_cast<float>(count(top[0]));
  if (static_cast<float>(count(top[1])) < tenth)
    top[1] = top[2] = -1;
  else if (static_cast<float>(count(top[2])) < tenth)
    top[2] = -1;

  std::vector<int> rejected;
  for (int b = 0; b < static_cast<int>(bins_.size()); ++b) {
    if (b == top[0] || b == top[1] || b == top[2]) continue;
    rejected.insert(rejected.end(), bins_[b].begin(), bins_[b].end());
  }
  std::sort(rejected.begin(), rejected.end());
  return rejected;
}

std::vector<Match> match_by_projection(const std::vector<ProjectedPoint>& points,
                                       const FrameView& frame, const ProjectionOptions& options,
                                       const std::vector<char>* taken) {
  check_descriptors(frame.descriptors, "frame");
  if (frame.descriptors.rows != static_cast<int>(frame.keypoints.size()))
    fail("ORB matcher: {} keypoints but {} descriptors", frame.keypoints.size(),
         frame.descriptors.rows);
  const int n_levels = frame.levels.size();
  std::vector<Match> candidates;
  std::vector<int> nearby;
  for (std::size_t p = 0; p < points.size(); ++p) {
    const ProjectedPoint& point = points[p];
    if (point.descriptor == nullptr) continue;
    const int level = std::clamp(point.level, 0, n_levels - 1);
    const float r = options.radius * point.radius_factor * frame.levels.scale[level];
    frame.grid.features_in_area(point.u, point.v, r, std::max(0, level - options.levels_below),
                                level + options.levels_above, nearby);
    Nearest nearest;
    for (int i : nearby) {
      if (taken && (*taken)[i]) continue;
      if (point.u_right >= 0.0f && frame.u_right && (*frame.u_right)[i] > 0.0f &&
          std::abs(point.u_right - (*frame.u_right)[i]) > r)
        continue;  // the depth disagrees
      nearest.offer(i,
                    descriptor_distance(point.descriptor, frame.descriptors.ptr<std::uint8_t>(i)),
                    frame.keypoints[i].octave);
    }
    if (nearest.best < 0 || nearest.best_distance > options.max_distance) continue;
    const bool ratio_applies =
        !options.ratio_same_level_only || nearest.best_level == nearest.second_level;
    if (ratio_applies && nearest.second_distance != INT_MAX &&
        static_cast<float>(nearest.best_distance) >
            options.nn_ratio * static_cast<float>(nearest.second_distance))
      continue;
    candidates.push_back({static_cast<int>(p), nearest.best, nearest.best_distance});
  }
  return keep_unique(std::move(candidates), frame.keypoints.size(), points, frame, options);
}

std::vector<Match> match_in_window(const std::vector<feature::OrbKeypoint>& first_keypoints,
                                   const cv::Mat& first_descriptors, const FrameView& second,
                                   const WindowOptions& options) {
  check_descriptors(first_descriptors, "first frame");
  if (first_descriptors.rows != static_cast<int>(first_keypoints.size()))
    fail("ORB matcher: {} keypoints but {} descriptors", first_keypoints.size(),
         first_descriptors.rows);
  std::vector<ProjectedPoint> points(first_keypoints.size());
  for (std::size_t i = 0; i < first_keypoints.size(); ++i) {
    const feature::OrbKeypoint& kp = first_keypoints[i];
    if (options.level0_only && kp.octave > 0) continue;  // descriptor stays null: skipped
    points[i] = {
        kp.x,     kp.y, -1.0f, kp.octave, first_descriptors.ptr<std::uint8_t>(static_cast<int>(i)),
        kp.angle, 1.0f};
  }
  ProjectionOptions projection;
  // The window is in level-0 pixels for every octave, and only the same octave is searched.
  projection.radius = options.window;
  projection.levels_below = projection.levels_above = 0;
  projection.nn_ratio = options.nn_ratio;
  projection.ratio_same_level_only = false;
  projection.max_distance = options.max_distance;
  projection.check_orientation = options.check_orientation;
  for (ProjectedPoint& p : points)
    p.radius_factor = 1.0f / second.levels.scale[std::clamp(p.level, 0, second.levels.size() - 1)];
  return match_by_projection(points, second, projection);
}

cv::Mat descriptor_rows(const cv::Mat& descriptors, const std::vector<std::size_t>& rows) {
  cv::Mat out(static_cast<int>(rows.size()), descriptors.cols, descriptors.type());
  for (std::size_t j = 0; j < rows.size(); ++j)
    descriptors.row(static_cast<int>(rows[j])).copyTo(out.row(static_cast<int>(j)));
  return out;
}

std::vector<Match> match_brute_force(const cv::Mat& query, const cv::Mat& train,
                                     const BruteForceOptions& options) {
  check_descriptors(query, "query");
  check_descriptors(train, "train");
  const int nq = query.rows, nt = train.rows;
  std::vector<Nearest> forward(nq);
  std::vector<int> backward_best(nt, -1), backward_distance(nt, INT_MAX);
  for (int q = 0; q < nq; ++q) {
    const std::uint8_t* dq = query.ptr<std::uint8_t>(q);
    Nearest& nearest = forward[q];
    for (int t = 0; t < nt; ++t) {
      const int d = descriptor_distance(dq, train.ptr<std::uint8_t>(t));
      nearest.offer(t, d, 0);
      if (d < backward_distance[t]) {  // the first query wins ties, as a forward search would
        backward_distance[t] = d;
        backward_best[t] = q;
      }
    }
  }
  std::vector<Match> matches;
  for (int q = 0; q < nq; ++q) {
    const Nearest& n = forward[q];
    if (n.best < 0 || n.best_distance > options.max_distance) continue;
    if (options.nn_ratio < 1.0f && n.second_distance != INT_MAX &&
        static_cast<float>(n.best_distance) >=
            options.nn_ratio * static_cast<float>(n.second_distance))
      continue;
    if (options.cross_check && backward_best[n.best] != q) continue;
    matches.push_back({q, n.best, n.best_distance});
  }
  return matches;
}

}  // namespace sbaslam::match
