#include "sbaslam/feature/stereo_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <utility>

#include "sbaslam/core/error.h"
#include "sbaslam/core/parallel_tasks.h"
#include "sbaslam/core/side_worker.h"
#include "sbaslam/feature/band_sad.h"
#include "sbaslam/match/hamming.h"

namespace sbaslam::feature {
namespace {

// Right keypoints by image row: each one is listed in every row within +-2 scale of its own
// (compressed-row layout: one allocation instead of one vector per row).
struct RowIndex {
  std::vector<int> starts;  // rows + 1
  std::vector<int> entries;

  RowIndex(const std::vector<OrbKeypoint>& keypoints, const ScaleLevels& levels, int rows) {
    starts.assign(rows + 1, 0);
    auto band = [&](const OrbKeypoint& kp, int& lo, int& hi) {
      const float r = 2.0f * levels.scale[kp.octave];
      lo = std::max(0, static_cast<int>(std::floor(kp.y - r)));
      hi = std::min(rows - 1, static_cast<int>(std::ceil(kp.y + r)));
    };
    int lo = 0, hi = 0;
    for (const OrbKeypoint& kp : keypoints) {
      band(kp, lo, hi);
      for (int row = lo; row <= hi; ++row) ++starts[row + 1];
    }
    for (int row = 0; row < rows; ++row) starts[row + 1] += starts[row];
    entries.resize(starts[rows]);
    std::vector<int> fill(starts.begin(), starts.end() - 1);
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      band(keypoints[i], lo, hi);
      for (int row = lo; row <= hi; ++row) entries[fill[row]++] = static_cast<int>(i);
    }
  }
};

// Best right keypoint by descriptor for left keypoint `i`, or -1.
int best_descriptor_match(const OrbFeatures& left, const OrbFeatures& right, int i,
                          const RowIndex& rows, float max_disparity, int threshold) {
  const OrbKeypoint& kp = left.keypoints[i];
  const int row = static_cast<int>(kp.y);
  if (row < 0 || row + 1 >= static_cast<int>(rows.starts.size())) return -1;
  const float min_u = kp.x - max_disparity, max_u = kp.x;
  const std::uint8_t* desc = left.descriptors.ptr<std::uint8_t>(i);
  int best = -1, best_distance = 100;  // ORB-SLAM's TH_HIGH
  for (int e = rows.starts[row]; e < rows.starts[row + 1]; ++e) {
    const int j = rows.entries[e];
    const OrbKeypoint& r = right.keypoints[j];
    if (r.octave < kp.octave - 1 || r.octave > kp.octave + 1) continue;
    if (r.x < min_u || r.x > max_u) continue;
    const int distance = match::descriptor_distance(desc, right.descriptors.ptr<std::uint8_t>(j));
    if (distance < best_distance) {
      best_distance = distance;
      best = j;
    }
  }
  return best_distance < threshold ? best : -1;
}

struct Refined {
  float u_right;
  int sad;
};

// Slides the left window along the right row at the left keypoint's level. False when the window
// leaves the image, the minimum is at the end of the range or the parabola is degenerate.
bool refine_by_sad(const OrbKeypoint& kp, float u_right0, const cv::Mat& left_level,
                   const cv::Mat& right_level, const ScaleLevels& levels,
                   const StereoMatchOptions& o, Refined& out) {
  const float inv = levels.inv_scale[kp.octave];
  const int ul = static_cast<int>(std::lround(kp.x * inv));
  const int vl = static_cast<int>(std::lround(kp.y * inv));
  const int ur0 = static_cast<int>(std::lround(u_right0 * inv));
  const int w = o.window_half, L = o.search_half, size = 2 * w + 1;
  // The SAD reads 16 bytes per window row, so a row below the window must exist.
  if (vl - w < 0 || vl + w + 1 >= left_level.rows || ul - w < 0 || ul + w >= left_level.cols)
    return false;
  if (vl + w + 1 >= right_level.rows || ur0 - L - w < 0 || ur0 + L + w >= right_level.cols)
    return false;

  // The left window beside the right one at the band's first position (shift -L).
  const WindowPair first{left_level.ptr<std::uint8_t>(vl - w) + (ul - w), left_level.step1(),
                         right_level.ptr<std::uint8_t>(vl - w) + (ur0 - L - w), right_level.step1(),
                         size};
  const BandSad band(first, 2 * L + 1, o.zero_mean);
  int distances[2 * kMaxSadSearch + 1];
  int best_sad = INT_MAX, best_shift = 0;
  for (int shift = -L; shift <= L; ++shift) {
    const int sad = band.at(shift + L);
    distances[shift + L] = sad;
    if (sad < best_sad) {
      best_sad = sad;
      best_shift = shift;
    }
  }
  if (best_shift == -L || best_shift == L) return false;
  const float d1 = static_cast<float>(distances[L + best_shift - 1]);
  const float d2 = static_cast<float>(distances[L + best_shift]);
  const float d3 = static_cast<float>(distances[L + best_shift + 1]);
  const float delta = (d1 - d3) / (2.0f * (d1 + d3 - 2.0f * d2));
  if (!(std::abs(delta) <= 1.0f)) return false;  // also rejects NaN from a flat profile
  out.u_right = levels.scale[kp.octave] * (static_cast<float>(ur0 + best_shift) + delta);
  out.sad = best_sad;
  return true;
}

// Everything one matching pass reads, shared by the threads that match parts of it.
struct MatchInputs {
  const OrbFeatures& left;
  const OrbFeatures& right;
  const std::vector<cv::Mat>& left_pyramid;
  const std::vector<cv::Mat>& right_pyramid;
  const ScaleLevels& levels;
  const StereoRig& rig;
  const StereoMatchOptions& options;
};

void check_inputs(const MatchInputs& in) {
  if (in.left_pyramid.empty() || in.right_pyramid.empty() ||
      in.left_pyramid[0].size() != in.right_pyramid[0].size())
    fail("stereo matching: left and right images must have the same size");
  if (!(in.rig.bf > 0.0 && in.rig.baseline > 0.0))
    fail("stereo matching: baseline and bf must be positive (got {} m, {})", in.rig.baseline,
         in.rig.bf);
  if (in.options.window_half < 0 || in.options.window_half * 2 + 1 > kMaxSadWindow ||
      in.options.search_half < 1 || in.options.search_half > kMaxSadSearch)
    fail("stereo matching: window half-size must be <= 7 and search half-range in [1, 30]");
}

// Matches left keypoints [begin, end): writes their entries of `out` (sized beforehand, so
// threads working on disjoint ranges never touch the same element) and appends (SAD, index) of
// each match to `sad_and_index`.
void match_range(const MatchInputs& in, const RowIndex& rows, int begin, int end,
                 StereoMatches& out, std::vector<std::pair<int, int>>& sad_and_index) {
  // Nearest depth is one baseline (ORB-SLAM's minZ), so the largest disparity is fx.
  const auto max_disparity = static_cast<float>(in.rig.bf / in.rig.baseline);
  for (int i = begin; i < end; ++i) {
    const int j = best_descriptor_match(in.left, in.right, i, rows, max_disparity,
                                        in.options.descriptor_threshold);
    if (j < 0) continue;
    const OrbKeypoint& kp = in.left.keypoints[i];
    Refined refined{};
    if (!refine_by_sad(kp, in.right.keypoints[j].x, in.left_pyramid[kp.octave],
                       in.right_pyramid[kp.octave], in.levels, in.options, refined))
      continue;
    float disparity = kp.x - refined.u_right;
    if (disparity < 0.0f || disparity >= max_disparity) continue;
    if (disparity <= 0.0f) {  // a point at infinity: keep it, at a large finite depth
      disparity = 0.01f;
      refined.u_right = kp.x - disparity;
    }
    out.depth[i] = static_cast<float>(in.rig.bf / disparity);
    out.u_right[i] = refined.u_right;
    sad_and_index.emplace_back(refined.sad, i);
  }
}

// Matches alternate blocks of left keypoints, those of index parity (0 or 1): keypoints run by
// octave and coarser octaves search wider row bands, so alternating blocks share the work between
// two threads more evenly than halves; blocks of 64 keep the threads' writes on separate cache
// lines.
void match_alternate_blocks(const MatchInputs& in, const RowIndex& rows, int parity,
                            StereoMatches& out, std::vector<std::pair<int, int>>& sad_and_index) {
  constexpr int kBlock = 64;
  const int n = static_cast<int>(in.left.size());
  for (int begin = parity * kBlock; begin < n; begin += 2 * kBlock)
    match_range(in, rows, begin, std::min(n, begin + kBlock), out, sad_and_index);
}

// Matches whose best SAD is far above the typical one are likely wrong. Sorting the (SAD, index)
// pairs makes the result independent of the order the threads appended them in.
void reject_outliers(std::vector<std::pair<int, int>>& sad_and_index, float factor,
                     StereoMatches& out) {
  if (sad_and_index.empty()) return;
  std::sort(sad_and_index.begin(), sad_and_index.end());
  const float median = static_cast<float>(sad_and_index[sad_and_index.size() / 2].first);
  const float threshold = factor * median;
  for (auto it = sad_and_index.rbegin(); it != sad_and_index.rend(); ++it) {
    if (static_cast<float>(it->first) < threshold) break;
    out.depth[it->second] = -1.0f;
    out.u_right[it->second] = -1.0f;
  }
}

void reset(StereoMatches& out, std::size_t n) {
  out.depth.assign(n, -1.0f);
  out.u_right.assign(n, -1.0f);
}

}  // namespace

int StereoMatches::count() const {
  return static_cast<int>(std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0; }));
}

StereoMatches match_stereo(const OrbFeatures& left, const OrbFeatures& right,
                           const std::vector<cv::Mat>& left_pyramid,
                           const std::vector<cv::Mat>& right_pyramid, const ScaleLevels& levels,
                           const StereoRig& rig, const StereoMatchOptions& options) {
  const MatchInputs in{left, right, left_pyramid, right_pyramid, levels, rig, options};
  check_inputs(in);
  StereoMatches out;
  reset(out, left.size());
  const RowIndex rows(right.keypoints, levels, left_pyramid[0].rows);
  std::vector<std::pair<int, int>> sad_and_index;
  sad_and_index.reserve(left.size());
  match_range(in, rows, 0, static_cast<int>(left.size()), out, sad_and_index);
  reject_outliers(sad_and_index, options.outlier_factor, out);
  return out;
}

StereoExtractor::StereoExtractor(const OrbSettings& settings, const StereoRig& rig,
                                 const StereoMatchOptions& options)
    : left_(settings), right_(settings), rig_(rig), options_(options) {
  if (!(rig.bf > 0.0 && rig.baseline > 0.0))
    fail("stereo extractor: baseline and bf must be positive (got {} m, {})", rig.baseline, rig.bf);
  worker_ = std::make_unique<SideWorker>();
}

StereoExtractor::~StereoExtractor() = default;

void StereoExtractor::extract_images(const cv::Mat& left, const cv::Mat& right, StereoFeatures& out,
                                     const std::function<void()>& beside) {
  if (!beside) {
    // Each image whole on one core: its pyramid stays in that core's cache (per-level tasks cost
    // 0.14 ms per EuRoC frame more, docs/RESULTS.md "Session 17").
    worker_->run_beside([&] { right_.extract(right, out.right); },
                        [&] { left_.extract(left, out.left); });
    return;
  }
  worker_->run_beside([&] { right_.begin(right); }, [&] { left_.begin(left); });
  // `beside` first, as the longest task (inference: ~2 ms against ~1 ms for a level-0 image),
  // then both images' levels, largest first. On OpenCV's threads: inside them the inference's
  // own parallel loops run serially and leave the other core to the levels.
  std::vector<std::function<void()>> tasks{beside};
  for (int level = 0; level < left_.levels().size(); ++level) {
    tasks.push_back([this, level] { left_.extract_level(level); });
    tasks.push_back([this, level] { right_.extract_level(level); });
  }
  run_tasks_in_parallel(tasks);
  left_.finish(out.left);
  right_.finish(out.right);
}

void StereoExtractor::extract(const cv::Mat& left, const cv::Mat& right, StereoFeatures& out,
                              const std::function<void()>& beside) {
  if (left.size() != right.size())
    fail("stereo extractor: left image is {}x{} but right image is {}x{}", left.cols, left.rows,
         right.cols, right.rows);
  extract_images(left, right, out, beside);

  const MatchInputs in{out.left,       out.right, left_.pyramid(), right_.pyramid(),
                       left_.levels(), rig_,      options_};
  check_inputs(in);
  reset(out.matches, out.left.size());
  const RowIndex rows(out.right.keypoints, left_.levels(), left_.pyramid()[0].rows);
  std::vector<std::pair<int, int>> first, second;
  first.reserve(out.left.size());
  second.reserve(out.left.size() / 2);
  worker_->run_beside([&] { match_alternate_blocks(in, rows, 1, out.matches, second); },
                      [&] { match_alternate_blocks(in, rows, 0, out.matches, first); });
  first.insert(first.end(), second.begin(), second.end());
  reject_outliers(first, options_.outlier_factor, out.matches);
}

}  // namespace sbaslam::feature
