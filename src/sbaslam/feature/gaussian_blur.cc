#include "sbaslam/feature/gaussian_blur.h"

#include <algorithm>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "sbaslam/core/error.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__GNUC__) && defined(__x86_64__)
// AVX2 versions are compiled beside the baseline ones and chosen at run time, so the build needs
// no -march flag and still runs on any x86-64.
#define SBASLAM_BLUR_AVX2 1
#include <immintrin.h>
#endif

namespace sbaslam::feature {
namespace {

// OpenCV's fixed-point taps for ksize 7, sigma 2: centre, then distance 1, 2 and 3 (sum 256).
constexpr int kTap0 = 56, kTap1 = 48, kTap2 = 34, kTap3 = 18;
// Horizontal sums reach 255 * 256; stored minus this bias they fit int16, which
// _mm_madd_epi16 needs.
constexpr int kBias = 1 << 15;
// Added to the vertical sum of biased values: the bias times the kernel sum, plus one half for
// rounding the 16 fractional bits.
constexpr int kVerticalOffset = kBias * 256 + kBias;
// Rows of horizontal sums kept: the 7 of the window, rounded up.
constexpr int kRing = 8;

int reflect101(int i, int n) {
  if (i < 0) return -i;
  return i >= n ? 2 * n - 2 - i : i;
}

// The row with 3 reflected pixels on each side: padded[x + k] is the pixel at x + k - 3.
void pad_row(const std::uint8_t* src, int cols, std::uint8_t* padded) {
  std::memcpy(padded + 3, src, static_cast<std::size_t>(cols));
  for (int k = 1; k <= 3; ++k) {
    padded[3 - k] = src[k];
    padded[cols + 2 + k] = src[cols - 1 - k];
  }
}

#if SBASLAM_BLUR_AVX2
// 16 pixels per step; returns the first x it did not do.
__attribute__((target("avx2"))) int horizontal_row_avx2(const std::uint8_t* padded, int cols,
                                                        std::int16_t* out) {
  const __m256i bias = _mm256_set1_epi16(static_cast<short>(0x8000));
  const __m256i t0 = _mm256_set1_epi16(kTap0), t1 = _mm256_set1_epi16(kTap1),
                t2 = _mm256_set1_epi16(kTap2), t3 = _mm256_set1_epi16(kTap3);
  int x = 0;
  for (; x + 16 <= cols; x += 16) {
    __m256i w[7];
    for (int k = 0; k < 7; ++k)
      w[k] =
          _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(padded + x + k)));
    const __m256i outer = _mm256_mullo_epi16(_mm256_add_epi16(w[0], w[6]), t3);
    const __m256i middle = _mm256_mullo_epi16(_mm256_add_epi16(w[1], w[5]), t2);
    const __m256i inner = _mm256_mullo_epi16(_mm256_add_epi16(w[2], w[4]), t1);
    const __m256i sum = _mm256_add_epi16(_mm256_add_epi16(outer, middle),
                                         _mm256_add_epi16(inner, _mm256_mullo_epi16(w[3], t0)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x), _mm256_xor_si256(sum, bias));
  }
  return x;
}

__attribute__((target("avx2"))) int vertical_row_avx2(const std::int16_t* const (&rows)[7],
                                                      int cols, std::uint8_t* dst) {
  const __m256i zero = _mm256_setzero_si256(), offset = _mm256_set1_epi32(kVerticalOffset);
  const __m256i t0 = _mm256_set1_epi16(kTap0), t1 = _mm256_set1_epi16(kTap1),
                t2 = _mm256_set1_epi16(kTap2), t3 = _mm256_set1_epi16(kTap3);
  int x = 0;
  for (; x + 16 <= cols; x += 16) {
    __m256i a[7];
    for (int k = 0; k < 7; ++k)
      a[k] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows[k] + x));
    // Unpacking works within 128-bit lanes; packing below undoes the same interleave.
    const __m256i lo = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(a[0], a[6]), t3),
                         _mm256_madd_epi16(_mm256_unpacklo_epi16(a[1], a[5]), t2)),
        _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(a[2], a[4]), t1),
                         _mm256_madd_epi16(_mm256_unpacklo_epi16(a[3], zero), t0)));
    const __m256i hi = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(a[0], a[6]), t3),
                         _mm256_madd_epi16(_mm256_unpackhi_epi16(a[1], a[5]), t2)),
        _mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(a[2], a[4]), t1),
                         _mm256_madd_epi16(_mm256_unpackhi_epi16(a[3], zero), t0)));
    const __m256i words = _mm256_packs_epi32(_mm256_srai_epi32(_mm256_add_epi32(lo, offset), 16),
                                             _mm256_srai_epi32(_mm256_add_epi32(hi, offset), 16));
    const __m256i bytes = _mm256_packus_epi16(words, words);  // per lane: 8 pixels, twice
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + x),
                     _mm256_castsi256_si128(_mm256_permute4x64_epi64(bytes, 0x08)));
  }
  return x;
}

bool has_avx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}
#endif

void horizontal_row(const std::uint8_t* padded, int cols, std::int16_t* out) {
  int x = 0;
#if SBASLAM_BLUR_AVX2
  if (has_avx2()) x = horizontal_row_avx2(padded, cols, out);
#endif
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128(), bias = _mm_set1_epi16(static_cast<short>(0x8000));
  const __m128i t0 = _mm_set1_epi16(kTap0), t1 = _mm_set1_epi16(kTap1), t2 = _mm_set1_epi16(kTap2),
                t3 = _mm_set1_epi16(kTap3);
  // Unsigned sums below 2^16 are exact in 16-bit lanes; the bias is a flip of the top bit.
  auto sums = [&](const __m128i(&w)[7]) {
    const __m128i outer = _mm_mullo_epi16(_mm_add_epi16(w[0], w[6]), t3);
    const __m128i middle = _mm_mullo_epi16(_mm_add_epi16(w[1], w[5]), t2);
    const __m128i inner = _mm_mullo_epi16(_mm_add_epi16(w[2], w[4]), t1);
    const __m128i sum = _mm_add_epi16(_mm_add_epi16(outer, middle),
                                      _mm_add_epi16(inner, _mm_mullo_epi16(w[3], t0)));
    return _mm_xor_si128(sum, bias);
  };
  for (; x + 16 <= cols; x += 16) {
    __m128i lo[7], hi[7];
    for (int k = 0; k < 7; ++k) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(padded + x + k));
      lo[k] = _mm_unpacklo_epi8(v, zero);
      hi[k] = _mm_unpackhi_epi8(v, zero);
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), sums(lo));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x + 8), sums(hi));
  }
#endif
  for (; x < cols; ++x) {
    const std::uint8_t* p = padded + x;
    const int h =
        kTap3 * (p[0] + p[6]) + kTap2 * (p[1] + p[5]) + kTap1 * (p[2] + p[4]) + kTap0 * p[3];
    out[x] = static_cast<std::int16_t>(h - kBias);
  }
}

// rows[k] holds the horizontal sums of image row y + k - 3 (reflected at the borders).
void vertical_row(const std::int16_t* const (&rows)[7], int cols, std::uint8_t* dst) {
  int x = 0;
#if SBASLAM_BLUR_AVX2
  if (has_avx2()) x = vertical_row_avx2(rows, cols, dst);
#endif
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128(), offset = _mm_set1_epi32(kVerticalOffset);
  const __m128i t0 = _mm_set1_epi16(kTap0), t1 = _mm_set1_epi16(kTap1), t2 = _mm_set1_epi16(kTap2),
                t3 = _mm_set1_epi16(kTap3);
  // Pairs of rows with the same tap, interleaved, give 32-bit tap * (a + b) in one madd.
  auto half = [&](const __m128i(&a)[7], bool high) {
    auto pair = [&](const __m128i& u, const __m128i& v, const __m128i& tap) {
      return _mm_madd_epi16(high ? _mm_unpackhi_epi16(u, v) : _mm_unpacklo_epi16(u, v), tap);
    };
    const __m128i sum = _mm_add_epi32(_mm_add_epi32(pair(a[0], a[6], t3), pair(a[1], a[5], t2)),
                                      _mm_add_epi32(pair(a[2], a[4], t1), pair(a[3], zero, t0)));
    return _mm_srai_epi32(_mm_add_epi32(sum, offset), 16);
  };
  for (; x + 8 <= cols; x += 8) {
    __m128i a[7];
    for (int k = 0; k < 7; ++k)
      a[k] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rows[k] + x));
    const __m128i words = _mm_packs_epi32(half(a, false), half(a, true));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(dst + x), _mm_packus_epi16(words, words));
  }
#endif
  for (; x < cols; ++x) {
    const int sum = kTap3 * (rows[0][x] + rows[6][x]) + kTap2 * (rows[1][x] + rows[5][x]) +
                    kTap1 * (rows[2][x] + rows[4][x]) + kTap0 * rows[3][x];
    dst[x] = static_cast<std::uint8_t>((sum + kVerticalOffset) >> 16);
  }
}

}  // namespace

void GaussianBlur7::apply(const cv::Mat& src, cv::Mat& dst) {
  if (src.type() != CV_8UC1) fail("Gaussian blur: expected an 8-bit single-channel image");
  if (src.rows < 4 || src.cols < 4) {  // reflection would fold more than once
    cv::GaussianBlur(src, dst, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
    return;
  }
  if (dst.size() != src.size() || dst.type() != CV_8UC1) dst.create(src.size(), CV_8UC1);
  const int rows = src.rows, cols = src.cols;
  padded_row_.resize(static_cast<std::size_t>(cols) + 6);
  // Output row y needs the horizontal sums of rows y - 3 .. y + 3 (reflected ones among them), so
  // a ring of 8 rows, each computed once, stays in the L1 cache where a whole-image buffer would
  // not.
  horizontal_.resize(static_cast<std::size_t>(kRing) * cols);
  auto ring_row = [&](int row) {
    return horizontal_.data() + static_cast<std::size_t>(row % kRing) * cols;
  };
  int computed = 0;  // rows [0, computed) have been through the horizontal pass
  for (int y = 0; y < rows; ++y) {
    for (; computed <= std::min(y + 3, rows - 1); ++computed) {
      pad_row(src.ptr<std::uint8_t>(computed), cols, padded_row_.data());
      horizontal_row(padded_row_.data(), cols, ring_row(computed));
    }
    const std::int16_t* window[7];
    for (int k = 0; k < 7; ++k) window[k] = ring_row(reflect101(y + k - 3, rows));
    vertical_row(window, cols, dst.ptr<std::uint8_t>(y));
  }
}

}  // namespace sbaslam::feature
