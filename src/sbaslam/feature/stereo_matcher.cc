#include "sbaslam/feature/stereo_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <future>

#include "sbaslam/core/error.h"
#include "sbaslam/match/hamming.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// Sum of absolute differences over a size x size window (size <= 16); `left` and `right` point
// at the windows' top-left pixels. Reads 16 bytes per row, so a row must follow the window's last
// one (keypoints sit kEdgeThreshold px inside the image, so one does).
int window_sad(const std::uint8_t* left, std::size_t left_step, const std::uint8_t* right,
               std::size_t right_step, int size) {
#if defined(__SSE2__)
  alignas(16) std::uint8_t mask_bytes[16];
  for (int i = 0; i < 16; ++i) mask_bytes[i] = i < size ? 0xff : 0;
  const __m128i mask = _mm_load_si128(reinterpret_cast<const __m128i*>(mask_bytes));
  __m128i acc = _mm_setzero_si128();
  for (int r = 0; r < size; ++r) {
    const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(left + r * left_step));
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(right + r * right_step));
    acc = _mm_add_epi64(acc, _mm_sad_epu8(_mm_and_si128(l, mask), _mm_and_si128(x, mask)));
  }
  return _mm_cvtsi128_si32(acc) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(acc, acc));
#else
  int sad = 0;
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c)
      sad += std::abs(static_cast<int>(left[r * left_step + c]) -
                      static_cast<int>(right[r * right_step + c]));
  return sad;
#endif
}

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

  const std::uint8_t* left_window = left_level.ptr<std::uint8_t>(vl - w) + (ul - w);
  int distances[64];
  int best_sad = INT_MAX, best_shift = 0;
  for (int shift = -L; shift <= L; ++shift) {
    const std::uint8_t* right_window = right_level.ptr<std::uint8_t>(vl - w) + (ur0 + shift - w);
    const int sad =
        window_sad(left_window, left_level.step1(), right_window, right_level.step1(), size);
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

}  // namespace

int StereoMatches::count() const {
  return static_cast<int>(std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0; }));
}

StereoMatches match_stereo(const OrbFeatures& left, const OrbFeatures& right,
                           const std::vector<cv::Mat>& left_pyramid,
                           const std::vector<cv::Mat>& right_pyramid, const ScaleLevels& levels,
                           const StereoRig& rig, const StereoMatchOptions& options) {
  if (left_pyramid.empty() || right_pyramid.empty() ||
      left_pyramid[0].size() != right_pyramid[0].size())
    fail("stereo matching: left and right images must have the same size");
  if (!(rig.bf > 0.0 && rig.baseline > 0.0))
    fail("stereo matching: baseline and bf must be positive (got {} m, {})", rig.baseline, rig.bf);
  if (options.window_half * 2 + 1 > 16 || options.search_half < 1 || options.search_half > 30)
    fail("stereo matching: window half-size must be <= 7 and search half-range in [1, 30]");

  const std::size_t n = left.size();
  StereoMatches out;
  out.depth.assign(n, -1.0f);
  out.u_right.assign(n, -1.0f);
  const RowIndex rows(right.keypoints, levels, left_pyramid[0].rows);
  // Nearest depth is one baseline (ORB-SLAM's minZ), so the largest disparity is fx.
  const auto max_disparity = static_cast<float>(rig.bf / rig.baseline);

  std::vector<std::pair<int, int>> sad_and_index;
  sad_and_index.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int j = best_descriptor_match(left, right, static_cast<int>(i), rows, max_disparity,
                                        options.descriptor_threshold);
    if (j < 0) continue;
    const OrbKeypoint& kp = left.keypoints[i];
    Refined refined{};
    if (!refine_by_sad(kp, right.keypoints[j].x, left_pyramid[kp.octave], right_pyramid[kp.octave],
                       levels, options, refined))
      continue;
    float disparity = kp.x - refined.u_right;
    if (disparity < 0.0f || disparity >= max_disparity) continue;
    if (disparity <= 0.0f) {  // a point at infinity: keep it, at a large finite depth
      disparity = 0.01f;
      refined.u_right = kp.x - disparity;
    }
    out.depth[i] = static_cast<float>(rig.bf / disparity);
    out.u_right[i] = refined.u_right;
    sad_and_index.emplace_back(refined.sad, static_cast<int>(i));
  }
  if (sad_and_index.empty()) return out;

  // Matches whose best SAD is far above the typical one are likely wrong.
  std::sort(sad_and_index.begin(), sad_and_index.end());
  const float median = static_cast<float>(sad_and_index[sad_and_index.size() / 2].first);
  const float threshold = options.outlier_factor * median;
  for (auto it = sad_and_index.rbegin(); it != sad_and_index.rend(); ++it) {
    if (static_cast<float>(it->first) < threshold) break;
    out.depth[it->second] = -1.0f;
    out.u_right[it->second] = -1.0f;
  }
  return out;
}

StereoExtractor::StereoExtractor(const OrbSettings& settings, const StereoRig& rig,
                                 const StereoMatchOptions& options)
    : left_(settings), right_(settings), rig_(rig), options_(options) {
  if (!(rig.bf > 0.0 && rig.baseline > 0.0))
    fail("stereo extractor: baseline and bf must be positive (got {} m, {})", rig.baseline, rig.bf);
}

void StereoExtractor::extract(const cv::Mat& left, const cv::Mat& right, StereoFeatures& out) {
  if (left.size() != right.size())
    fail("stereo extractor: left image is {}x{} but right image is {}x{}", left.cols, left.rows,
         right.cols, right.rows);
  auto right_done = std::async(std::launch::async, [&] { right_.extract(right, out.right); });
  try {
    left_.extract(left, out.left);
  } catch (...) {
    right_done.wait();
    throw;
  }
  right_done.get();
  out.matches = match_stereo(out.left, out.right, left_.pyramid(), right_.pyramid(), left_.levels(),
                             rig_, options_);
}

}  // namespace sbaslam::feature
