#include "sbaslam/feature/band_sad.h"

#include <algorithm>
#include <cstdlib>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sbaslam::feature {
namespace {

// Columns of a searched band (window plus 2 * kMaxSadSearch positions), rounded up to 16.
constexpr int kMaxColumns = (kMaxSadWindow + 2 * kMaxSadSearch + 15) / 16 * 16;

#if defined(__SSE2__)
// Byte masks keeping the first `size` of 16 lanes, built once instead of once per window.
struct ByteMasks {
  alignas(16) std::uint8_t lanes[kMaxSadWindow + 1][16];
};

const ByteMasks& byte_masks() {
  static const ByteMasks masks = [] {
    ByteMasks m{};
    for (int size = 0; size <= kMaxSadWindow; ++size)
      for (int i = 0; i < 16; ++i) m.lanes[size][i] = i < size ? 0xff : 0;
    return m;
  }();
  return masks;
}

__m128i load_row(const std::uint8_t* p, const __m128i& mask) {
  return _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), mask);
}

int sum_halves(const __m128i& acc) {
  return _mm_cvtsi128_si32(acc) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(acc, acc));
}
#endif

#if !defined(__SSE2__)
int scalar_offset_sad(const WindowPair& w, int offset) {
  int sad = 0;
  for (int r = 0; r < w.size; ++r)
    for (int c = 0; c < w.size; ++c)
      sad += std::abs(static_cast<int>(w.left[r * w.left_step + c]) -
                      static_cast<int>(w.right[r * w.right_step + c]) - offset);
  return sad;
}
#endif

// Round-half-away-from-zero of a / b for b > 0 (never exactly half here: b is an odd square).
int rounded_quotient(int a, int b) {
  return a >= 0 ? (2 * a + b) / (2 * b) : -((-2 * a + b) / (2 * b));
}

#if defined(__SSE2__)
// SAD of `moved` raised (or lowered) by `shift` against `other`, over size x size windows.
int moved_sad(const std::uint8_t* moved, std::size_t moved_step, const std::uint8_t* other,
              std::size_t other_step, int size, int shift, bool raise) {
  const __m128i mask = _mm_load_si128(reinterpret_cast<const __m128i*>(byte_masks().lanes[size]));
  const __m128i amount = _mm_set1_epi8(static_cast<char>(shift));
  __m128i acc = _mm_setzero_si128();
  for (int r = 0; r < size; ++r) {
    const __m128i m = load_row(moved + r * moved_step, mask);
    const __m128i o = load_row(other + r * other_step, mask);
    acc = _mm_add_epi64(
        acc, _mm_sad_epu8(raise ? _mm_adds_epu8(m, amount) : _mm_subs_epu8(m, amount), o));
  }
  // Raised, the masked-off lanes hold `shift` against 0 (lowered, 0 against 0).
  return sum_halves(acc) - (raise ? size * (16 - size) * shift : 0);
}

// The exact sum in 16-bit lanes: |difference| <= 510, and a lane adds two columns over at most
// 16 rows, 16320 < 2^15.
int wide_offset_sad(const WindowPair& w, int offset) {
  const __m128i zero = _mm_setzero_si128(), off = _mm_set1_epi16(static_cast<short>(offset));
  const __m128i mask = _mm_load_si128(reinterpret_cast<const __m128i*>(byte_masks().lanes[w.size]));
  const __m128i mask_lo = _mm_unpacklo_epi8(mask, mask), mask_hi = _mm_unpackhi_epi8(mask, mask);
  __m128i acc = zero;
  for (int r = 0; r < w.size; ++r) {
    const __m128i l = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w.left + r * w.left_step));
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w.right + r * w.right_step));
    const __m128i lo =
        _mm_sub_epi16(_mm_sub_epi16(_mm_unpacklo_epi8(l, zero), _mm_unpacklo_epi8(x, zero)), off);
    const __m128i hi =
        _mm_sub_epi16(_mm_sub_epi16(_mm_unpackhi_epi8(l, zero), _mm_unpackhi_epi8(x, zero)), off);
    acc = _mm_add_epi16(
        acc, _mm_add_epi16(_mm_and_si128(_mm_max_epi16(lo, _mm_sub_epi16(zero, lo)), mask_lo),
                           _mm_and_si128(_mm_max_epi16(hi, _mm_sub_epi16(zero, hi)), mask_hi)));
  }
  const __m128i pairs = _mm_madd_epi16(acc, _mm_set1_epi16(1));
  const __m128i halves = _mm_add_epi32(pairs, _mm_unpackhi_epi64(pairs, pairs));
  return _mm_cvtsi128_si32(halves) + _mm_cvtsi128_si32(_mm_srli_si128(halves, 4));
}

int max_byte(__m128i v) {
  v = _mm_max_epu8(v, _mm_srli_si128(v, 8));
  v = _mm_max_epu8(v, _mm_srli_si128(v, 4));
  v = _mm_max_epu8(v, _mm_srli_si128(v, 2));
  v = _mm_max_epu8(v, _mm_srli_si128(v, 1));
  return _mm_cvtsi128_si32(v) & 0xff;
}
#endif

}  // namespace

BandSad::BandSad(const WindowPair& first, int positions, bool zero_mean) : first_(first) {
  if (zero_mean) prepare_offsets(positions);
}

int BandSad::at(int position) const {
  WindowPair w = first_;
  w.right += position;
  const int offset = offsets_[position];
#if defined(__SSE2__)
  // |left - right - offset| in 8-bit lanes: one window moved by |offset| with saturation, the
  // right one up or the left one down for a positive offset, the left one up or the right one
  // down for a negative one. Exact when nothing saturates, which the windows' extremes tell
  // (conservatively: those of the whole band); the 16-bit sum answers otherwise.
  const int shift = std::abs(offset);
  if (offset >= 0) {
    if (band_max_ + shift <= 255)
      return moved_sad(w.right, w.right_step, w.left, w.left_step, w.size, shift, true);
    if (left_min_ >= shift)
      return moved_sad(w.left, w.left_step, w.right, w.right_step, w.size, shift, false);
  } else {
    if (left_max_ + shift <= 255)
      return moved_sad(w.left, w.left_step, w.right, w.right_step, w.size, shift, true);
    if (band_min_ >= shift)
      return moved_sad(w.right, w.right_step, w.left, w.left_step, w.size, shift, false);
  }
  return wide_offset_sad(w, offset);
#else
  return scalar_offset_sad(w, offset);
#endif
}

void BandSad::prepare_offsets(int positions) {
  const int size = first_.size, columns = size + positions - 1;
  std::int16_t column_sum[kMaxColumns] = {};
  const int left_sum = sums_and_extremes(columns, column_sum);
  int window_sum = 0;
  for (int c = 0; c < size; ++c) window_sum += column_sum[c];
  for (int p = 0; p < positions; ++p) {
    if (p > 0) window_sum += column_sum[p + size - 1] - column_sum[p - 1];
    offsets_[p] = rounded_quotient(left_sum - window_sum, size * size);
  }
}

// Column sums are at most 16 * 255, so 16 bits hold them.
int BandSad::sums_and_extremes(int columns, std::int16_t* column_sum) {
  const int size = first_.size;
#if defined(__SSE2__)
  // 16-byte chunks over the band; the last one may read past it, into the image row or the
  // next row (which exists, see kMaxSadWindow), and is masked for the extremes.
  const int chunks = (columns + 15) / 16;
  const __m128i zero = _mm_setzero_si128();
  const __m128i window_mask =
      _mm_load_si128(reinterpret_cast<const __m128i*>(byte_masks().lanes[size]));
  __m128i lo[kMaxColumns / 16] = {}, hi[kMaxColumns / 16] = {};
  const __m128i ones = _mm_set1_epi8(static_cast<char>(0xff));
  __m128i band_max = zero, left_max = zero, left_sum = zero, band_min = ones, left_min = ones;
  for (int r = 0; r < size; ++r) {
    const std::uint8_t* band_row = first_.right + r * first_.right_step;
    for (int k = 0; k < chunks; ++k) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(band_row + 16 * k));
      lo[k] = _mm_add_epi16(lo[k], _mm_unpacklo_epi8(v, zero));
      hi[k] = _mm_add_epi16(hi[k], _mm_unpackhi_epi8(v, zero));
      const __m128i valid = _mm_load_si128(
          reinterpret_cast<const __m128i*>(byte_masks().lanes[std::min(16, columns - 16 * k)]));
      band_max = _mm_max_epu8(band_max, _mm_and_si128(v, valid));
      band_min = _mm_min_epu8(band_min, _mm_or_si128(v, _mm_andnot_si128(valid, ones)));
    }
    const __m128i l = load_row(first_.left + r * first_.left_step, window_mask);
    left_max = _mm_max_epu8(left_max, l);
    left_min = _mm_min_epu8(left_min, _mm_or_si128(l, _mm_andnot_si128(window_mask, ones)));
    left_sum = _mm_add_epi64(left_sum, _mm_sad_epu8(l, zero));
  }
  for (int k = 0; k < chunks; ++k) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(column_sum + 16 * k), lo[k]);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(column_sum + 16 * k + 8), hi[k]);
  }
  band_max_ = max_byte(band_max);
  left_max_ = max_byte(left_max);
  band_min_ = 255 - max_byte(_mm_xor_si128(band_min, ones));  // min(v) = 255 - max(255 - v)
  left_min_ = 255 - max_byte(_mm_xor_si128(left_min, ones));
  return sum_halves(left_sum);
#else
  int left_sum = 0;
  left_max_ = band_max_ = 0;
  left_min_ = band_min_ = 255;
  for (int r = 0; r < size; ++r) {
    const std::uint8_t* band_row = first_.right + r * first_.right_step;
    const std::uint8_t* left_row = first_.left + r * first_.left_step;
    for (int c = 0; c < columns; ++c) {
      column_sum[c] = static_cast<std::int16_t>(column_sum[c] + band_row[c]);
      band_max_ = std::max<int>(band_max_, band_row[c]);
      band_min_ = std::min<int>(band_min_, band_row[c]);
    }
    for (int c = 0; c < size; ++c) {
      left_sum += left_row[c];
      left_max_ = std::max<int>(left_max_, left_row[c]);
      left_min_ = std::min<int>(left_min_, left_row[c]);
    }
  }
  return left_sum;
#endif
}

}  // namespace sbaslam::feature
