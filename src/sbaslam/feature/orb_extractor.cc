#include "sbaslam/feature/orb_extractor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"
#include "sbaslam/core/parallel_tasks.h"
#include "sbaslam/feature/orb_pattern.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sbaslam::feature {
namespace {

constexpr int kCellSize = 35;  // ORB-SLAM's grid cell for FAST, in level pixels
constexpr int kFastRadius = 3;
// FAST runs on the level minus this margin; its own 3-pixel border then keeps keypoints
// kEdgeThreshold pixels inside, far enough for the rotated 31x31 patch.
constexpr int kFastMargin = kEdgeThreshold - kFastRadius;

float angle_of_moments(int m_01, int m_10) {
  float degrees = static_cast<float>(std::atan2(static_cast<double>(m_01), m_10) * 180.0 / M_PI);
  if (degrees < 0.0f) degrees += 360.0f;
  if (degrees >= 360.0f) degrees -= 360.0f;
  return degrees;
}

#if defined(__SSE2__)
// Per row distance v of the disc, the weights of the 32 pixels from u = -15 to 16: u (for m_10)
// and v (for m_01) inside the disc, 0 outside it. With them each row pair costs a few
// multiply-adds instead of a loop over up to 31 pixels; the integer sums, and so the angles, are
// those of the scalar loop.
struct MomentWeights {
  alignas(16) std::int16_t u[kHalfPatch + 1][32];
  alignas(16) std::int16_t v[kHalfPatch + 1][32];
};

const MomentWeights& moment_weights() {
  static const MomentWeights weights = [] {
    MomentWeights w{};
    const auto& umax = orientation_patch_umax();
    for (int v = 0; v <= kHalfPatch; ++v)
      for (int i = 0; i < 32; ++i) {
        const int u = i - kHalfPatch;
        const bool inside = std::abs(u) <= umax[v];
        w.u[v][i] = static_cast<std::int16_t>(inside ? u : 0);
        w.v[v][i] = static_cast<std::int16_t>(inside ? v : 0);
      }
    return w;
  }();
  return weights;
}

// Sum over 32 16-bit lanes (a, b: pixels u = -15..0 and 1..16) times the weights.
__m128i weighted(const __m128i (&lanes)[4], const std::int16_t* weights) {
  __m128i sum = _mm_setzero_si128();
  for (int k = 0; k < 4; ++k)
    sum = _mm_add_epi32(
        sum,
        _mm_madd_epi16(lanes[k], _mm_load_si128(reinterpret_cast<const __m128i*>(weights) + k)));
  return sum;
}

int horizontal_sum(__m128i v) {
  v = _mm_add_epi32(v, _mm_unpackhi_epi64(v, v));
  return _mm_cvtsi128_si32(v) + _mm_cvtsi128_si32(_mm_srli_si128(v, 4));
}

// The 32 pixels from u = -15 to 16 of a row, widened to 16 bits. Keypoints lie kEdgeThreshold
// (19) pixels inside the level, so the read of u = 16 stays in the image.
void widen_row(const std::uint8_t* center, __m128i (&out)[4]) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(center - kHalfPatch));
  const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(center - kHalfPatch + 16));
  out[0] = _mm_unpacklo_epi8(a, zero);
  out[1] = _mm_unpackhi_epi8(a, zero);
  out[2] = _mm_unpacklo_epi8(b, zero);
  out[3] = _mm_unpackhi_epi8(b, zero);
}

float intensity_centroid_angle(const cv::Mat& image, int x, int y) {
  const MomentWeights& w = moment_weights();
  const std::uint8_t* center = image.ptr<std::uint8_t>(y) + x;
  const auto step = static_cast<std::ptrdiff_t>(image.step1());
  __m128i row[4], below[4], above[4], sum[4], difference[4];
  widen_row(center, row);
  __m128i m_10 = weighted(row, w.u[0]), m_01 = _mm_setzero_si128();
  // Rows v and -v together: their u-moments add, their v-moments subtract.
  for (int v = 1; v <= kHalfPatch; ++v) {
    widen_row(center + v * step, below);
    widen_row(center - v * step, above);
    for (int k = 0; k < 4; ++k) {
      sum[k] = _mm_add_epi16(below[k], above[k]);
      difference[k] = _mm_sub_epi16(below[k], above[k]);
    }
    m_10 = _mm_add_epi32(m_10, weighted(sum, w.u[v]));
    m_01 = _mm_add_epi32(m_01, weighted(difference, w.v[v]));
  }
  return angle_of_moments(horizontal_sum(m_01), horizontal_sum(m_10));
}
#else
float intensity_centroid_angle(const cv::Mat& image, int x, int y) {
  const auto& umax = orientation_patch_umax();
  const std::uint8_t* center = image.ptr<std::uint8_t>(y) + x;
  const auto step = static_cast<std::ptrdiff_t>(image.step1());
  int m_01 = 0, m_10 = 0;
  for (int u = -kHalfPatch; u <= kHalfPatch; ++u) m_10 += u * center[u];
  // Rows v and -v are summed together: their u-moments add, their v-moments subtract.
  for (int v = 1; v <= kHalfPatch; ++v) {
    int v_sum = 0;
    const std::uint8_t* below = center + v * step;
    const std::uint8_t* above = center - v * step;
    const int d = umax[v];
    for (int u = -d; u <= d; ++u) {
      const int plus = below[u], minus = above[u];
      v_sum += plus - minus;
      m_10 += u * (plus + minus);
    }
    m_01 += v * v_sum;
  }
  return angle_of_moments(m_01, m_10);
}
#endif

// Pattern as two coordinate arrays, the layout the offset computation wants.
struct PatternArrays {
  alignas(16) float x[2 * kDescriptorBits];
  alignas(16) float y[2 * kDescriptorBits];
};

const PatternArrays& pattern_arrays() {
  static const PatternArrays arrays = [] {
    PatternArrays a{};
    const auto& pattern = brief_pattern();
    for (int i = 0; i < 2 * kDescriptorBits; ++i) {
      a.x[i] = pattern[i].x;
      a.y[i] = pattern[i].y;
    }
    return a;
  }();
  return arrays;
}

// Memory offsets of the rotated pattern points: row = round(x sin + y cos), col = round(x cos -
// y sin), rounding half to even as ORB-SLAM's cvRound.
void rotated_pattern_offsets(float angle_degrees, int step, int* offsets) {
  const float radians = angle_degrees * static_cast<float>(M_PI / 180.0);
  const float c = std::cos(radians), s = std::sin(radians);
  const PatternArrays& p = pattern_arrays();
#if defined(__SSE2__)
  const __m128 cv = _mm_set1_ps(c), sv = _mm_set1_ps(s),
               stepv = _mm_set1_ps(static_cast<float>(step));
  for (int i = 0; i < 2 * kDescriptorBits; i += 4) {
    const __m128 px = _mm_load_ps(p.x + i), py = _mm_load_ps(p.y + i);
    const __m128i row = _mm_cvtps_epi32(_mm_add_ps(_mm_mul_ps(px, sv), _mm_mul_ps(py, cv)));
    const __m128i col = _mm_cvtps_epi32(_mm_sub_ps(_mm_mul_ps(px, cv), _mm_mul_ps(py, sv)));
    // row * step + col is exact in float: |row| <= 14 and step < 2^20.
    const __m128 offset = _mm_add_ps(_mm_mul_ps(_mm_cvtepi32_ps(row), stepv), _mm_cvtepi32_ps(col));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(offsets + i), _mm_cvtps_epi32(offset));
  }
#else
  for (int i = 0; i < 2 * kDescriptorBits; ++i) {
    const long row = std::lrint(p.x[i] * s + p.y[i] * c);
    const long col = std::lrint(p.x[i] * c - p.y[i] * s);
    offsets[i] = static_cast<int>(row * step + col);
  }
#endif
}

void steered_brief(const cv::Mat& blurred, int x, int y, float angle_degrees, std::uint8_t* desc) {
  alignas(16) int offsets[2 * kDescriptorBits];
  rotated_pattern_offsets(angle_degrees, static_cast<int>(blurred.step1()), offsets);
  const std::uint8_t* center = blurred.ptr<std::uint8_t>(y) + x;
  for (int byte = 0; byte < kDescriptorBytes; ++byte) {
    const int* o = offsets + 16 * byte;
    unsigned value = 0;
    for (int bit = 0; bit < 8; ++bit)
      value |= static_cast<unsigned>(center[o[2 * bit]] < center[o[2 * bit + 1]]) << bit;
    desc[byte] = static_cast<std::uint8_t>(value);
  }
}

}  // namespace

ScaleLevels ScaleLevels::make(int n_levels, double scale_factor) {
  ScaleLevels levels;
  double scale = 1.0;
  for (int i = 0; i < n_levels; ++i) {
    levels.scale.push_back(static_cast<float>(scale));
    levels.inv_scale.push_back(static_cast<float>(1.0 / scale));
    levels.sigma2.push_back(static_cast<float>(scale * scale));
    levels.inv_sigma2.push_back(static_cast<float>(1.0 / (scale * scale)));
    scale *= scale_factor;
  }
  return levels;
}

void validate_orb_settings(const OrbSettings& s) {
  if (s.n_features <= 0)
    fail("ORB settings: ORBextractor.nFeatures must be > 0 (got {})", s.n_features);
  if (!(std::isfinite(s.scale_factor) && s.scale_factor > 1.0 && s.scale_factor <= 4.0))
    fail("ORB settings: ORBextractor.scaleFactor must be in (1, 4] (got {})", s.scale_factor);
  if (s.n_levels < 1 || s.n_levels > 32)
    fail("ORB settings: ORBextractor.nLevels must be in [1, 32] (got {})", s.n_levels);
  if (s.ini_th_fast < 1 || s.ini_th_fast > 254)
    fail("ORB settings: ORBextractor.iniThFAST must be in [1, 254] (got {})", s.ini_th_fast);
  if (s.min_th_fast < 1 || s.min_th_fast > s.ini_th_fast)
    fail("ORB settings: ORBextractor.minThFAST must be in [1, iniThFAST = {}] (got {})",
         s.ini_th_fast, s.min_th_fast);
}

std::vector<int> features_per_level(const OrbSettings& s) {
  std::vector<int> counts(s.n_levels, 0);
  const double ratio = 1.0 / s.scale_factor;
  double share = s.n_features * (1.0 - ratio) / (1.0 - std::pow(ratio, s.n_levels));
  int assigned = 0;
  for (int level = 0; level + 1 < s.n_levels; ++level) {
    counts[level] = static_cast<int>(std::lround(share));
    assigned += counts[level];
    share *= ratio;
  }
  counts[s.n_levels - 1] = std::max(s.n_features - assigned, 0);
  return counts;
}

OrbExtractor::OrbExtractor(const OrbSettings& settings) : settings_(settings) {
  validate_orb_settings(settings_);
  levels_ = ScaleLevels::make(settings_.n_levels, settings_.scale_factor);
  wanted_per_level_ = features_per_level(settings_);
  pyramid_.resize(settings_.n_levels);
  scratch_.resize(settings_.n_levels);
  level_features_.resize(settings_.n_levels);
}

void OrbExtractor::build_pyramid(const cv::Mat& image) {
  pyramid_[0] = image;
  for (int level = 1; level < settings_.n_levels; ++level) {
    const float inv = levels_.inv_scale[level];
    const cv::Size size(static_cast<int>(std::lround(image.cols * inv)),
                        static_cast<int>(std::lround(image.rows * inv)));
    if (size.width < 1 || size.height < 1) {
      pyramid_[level].release();
      continue;
    }
    // Each level from the previous one, bilinear, as ORB-SLAM.
    cv::resize(pyramid_[level - 1], pyramid_[level], size, 0, 0, cv::INTER_LINEAR);
  }
}

void OrbExtractor::add_fallback_corners(const cv::Mat& roi, const cv::Rect& cell,
                                        LevelScratch& work) const {
  // One pixel of context beyond the cell on each side (plus FAST's radius) so that non-maximum
  // suppression at the cell's edge sees the neighbours.
  const int pad = kFastRadius + 1;
  const cv::Rect window =
      cv::Rect(cell.x - pad, cell.y - pad, cell.width + 2 * pad, cell.height + 2 * pad) &
      cv::Rect(0, 0, roi.cols, roi.rows);
  cv::FAST(roi(window), work.cell_corners, settings_.min_th_fast, true);
  for (cv::KeyPoint kp : work.cell_corners) {
    kp.pt.x += static_cast<float>(window.x);
    kp.pt.y += static_cast<float>(window.y);
    if (cell.contains(cv::Point(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y))))
      work.candidates.push_back(kp);
  }
}

void OrbExtractor::detect_on_grid(const cv::Mat& level_image, LevelScratch& work) const {
  std::vector<cv::KeyPoint>& candidates = work.candidates;
  std::vector<int>& cell_counts = work.cell_counts;
  candidates.clear();
  const int width = level_image.cols - 2 * kFastMargin;
  const int height = level_image.rows - 2 * kFastMargin;
  if (width <= 2 * kFastRadius || height <= 2 * kFastRadius) return;
  const cv::Mat roi = level_image(cv::Rect(kFastMargin, kFastMargin, width, height));

  // FAST with non-maximum suppression over the whole level at the initial threshold gives what
  // ORB-SLAM's per-cell calls give (a corner's score does not depend on the threshold).
  cv::FAST(roi, candidates, settings_.ini_th_fast, true);

  // ORB-SLAM's cells: about 35 px, covering [3, size - 3) of the FAST region.
  const int n_cols = std::max(1, width / kCellSize), n_rows = std::max(1, height / kCellSize);
  const int cell_w = (width + n_cols - 1) / n_cols, cell_h = (height + n_rows - 1) / n_rows;
  cell_counts.assign(static_cast<std::size_t>(n_cols) * n_rows, 0);
  for (const cv::KeyPoint& kp : candidates) {
    const int col = std::min(n_cols - 1, (static_cast<int>(kp.pt.x) - kFastRadius) / cell_w);
    const int row = std::min(n_rows - 1, (static_cast<int>(kp.pt.y) - kFastRadius) / cell_h);
    ++cell_counts[row * n_cols + col];
  }
  if (settings_.min_th_fast < settings_.ini_th_fast) {
    const cv::Rect detectable(kFastRadius, kFastRadius, width - 2 * kFastRadius,
                              height - 2 * kFastRadius);
    // Runs of empty cells in a row share one FAST call: fewer, larger calls cost less.
    for (int row = 0; row < n_rows; ++row) {
      int col = 0;
      while (col < n_cols) {
        if (cell_counts[row * n_cols + col] > 0) {
          ++col;
          continue;
        }
        const int first = col;
        while (col < n_cols && cell_counts[row * n_cols + col] == 0) ++col;
        const cv::Rect cells = cv::Rect(kFastRadius + first * cell_w, kFastRadius + row * cell_h,
                                        (col - first) * cell_w, cell_h) &
                               detectable;
        if (cells.area() > 0) add_fallback_corners(roi, cells, work);
      }
    }
  }
  for (cv::KeyPoint& kp : candidates) {
    kp.pt.x += kFastMargin;
    kp.pt.y += kFastMargin;
  }
}

void OrbExtractor::describe_level(int level, LevelScratch& work, OrbFeatures& out) const {
  const cv::Mat& image = pyramid_[level];
  // The buffer keeps the size of the largest level it served, so it allocates nothing after the
  // first frame.
  if (work.blurred.rows < image.rows || work.blurred.cols < image.cols)
    work.blurred.create(image.size(), CV_8U);
  cv::Mat blurred = work.blurred(cv::Rect(0, 0, image.cols, image.rows));
  work.gaussian.apply(image, blurred);  // = cv::GaussianBlur 7x7, sigma 2, reflect-101

  const float scale = levels_.scale[level];
  out.keypoints.resize(work.kept.size());
  out.descriptors.create(static_cast<int>(work.kept.size()), kDescriptorBytes, CV_8U);
  for (std::size_t k = 0; k < work.kept.size(); ++k) {
    const cv::KeyPoint& c = work.candidates[work.kept[k]];
    const int x = static_cast<int>(c.pt.x), y = static_cast<int>(c.pt.y);
    OrbKeypoint& kp = out.keypoints[k];
    kp.angle = intensity_centroid_angle(image, x, y);
    kp.x = static_cast<float>(x) * scale;
    kp.y = static_cast<float>(y) * scale;
    kp.size = static_cast<float>(kPatchSize) * scale;
    kp.response = c.response;
    kp.octave = level;
    steered_brief(blurred, x, y, kp.angle, out.descriptors.ptr<std::uint8_t>(static_cast<int>(k)));
  }
}

void OrbExtractor::begin(const cv::Mat& image) {
  if (image.empty()) fail("ORB extractor: empty image");
  if (image.type() != CV_8UC1)
    fail("ORB extractor: expected an 8-bit single-channel image, got type {} with {} channels",
         image.depth(), image.channels());
  build_pyramid(image);
}

void OrbExtractor::extract_level(int level) {
  extract_level(level, scratch_[level]);
}

void OrbExtractor::extract_level(int level, LevelScratch& work) {
  OrbFeatures& out = level_features_[level];
  out.keypoints.clear();
  if (pyramid_[level].empty()) return;
  detect_on_grid(pyramid_[level], work);
  const cv::Size size = pyramid_[level].size();
  const cv::Rect2f region(kFastMargin, kFastMargin,
                          static_cast<float>(size.width - 2 * kFastMargin),
                          static_cast<float>(size.height - 2 * kFastMargin));
  work.quadtree.distribute(work.candidates, region, wanted_per_level_[level], work.kept);
  if (!work.kept.empty()) describe_level(level, work, out);
}

void OrbExtractor::finish(OrbFeatures& out) const {
  std::size_t total = 0;
  for (const OrbFeatures& level : level_features_) total += level.keypoints.size();
  out.keypoints.clear();
  out.keypoints.reserve(total);
  out.descriptors.create(static_cast<int>(total), kDescriptorBytes, CV_8U);
  int row = 0;
  for (const OrbFeatures& level : level_features_) {
    if (level.keypoints.empty()) continue;
    out.keypoints.insert(out.keypoints.end(), level.keypoints.begin(), level.keypoints.end());
    const int n = static_cast<int>(level.keypoints.size());
    level.descriptors.copyTo(out.descriptors.rowRange(row, row + n));
    row += n;
  }
}

void OrbExtractor::extract_sharing_cores(const cv::Mat& image, OrbFeatures& out,
                                         const std::function<void()>& beside) {
  begin(image);
  std::vector<std::function<void()>> tasks;
  if (beside) tasks.push_back(beside);
  for (int level = 0; level < settings_.n_levels; ++level)
    tasks.push_back([this, level] { extract_level(level); });
  run_tasks_in_parallel(tasks);
  finish(out);
}

void OrbExtractor::extract(const cv::Mat& image, OrbFeatures& out) {
  begin(image);
  for (int level = 0; level < settings_.n_levels; ++level) extract_level(level, scratch_[0]);
  finish(out);
}

}  // namespace sbaslam::feature
