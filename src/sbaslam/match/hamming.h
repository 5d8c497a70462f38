#pragma once
// Hamming distance between two 256-bit ORB descriptors (32 bytes each).
//
// On x86-64 without -mpopcnt (our default build: no -march=native), GCC compiles
// __builtin_popcountll into four calls to libgcc's __popcountdi2. The SSE2 path below (part of
// the x86-64 baseline) counts the bits of both 128-bit halves in registers instead: the classic
// bit-slice count to bytes, then psadbw sums the bytes. Other targets use the builtin, which
// becomes a native instruction there (e.g. AArch64's cnt).

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace sbaslam::match {

inline constexpr int kDescriptorBytes = 32;
inline constexpr int kMaxDescriptorDistance = 8 * kDescriptorBytes;

#if defined(__SSE2__)
namespace detail {
inline __m128i popcount_bytes(__m128i x) {
  const __m128i m1 = _mm_set1_epi8(0x55), m2 = _mm_set1_epi8(0x33), m4 = _mm_set1_epi8(0x0f);
  x = _mm_sub_epi8(x, _mm_and_si128(_mm_srli_epi64(x, 1), m1));
  x = _mm_add_epi8(_mm_and_si128(x, m2), _mm_and_si128(_mm_srli_epi64(x, 2), m2));
  return _mm_and_si128(_mm_add_epi8(x, _mm_srli_epi64(x, 4)), m4);
}
}  // namespace detail
#endif

inline int descriptor_distance(const std::uint8_t* a, const std::uint8_t* b) {
#if defined(__SSE2__) && !defined(__POPCNT__)
  const __m128i lo = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a)),
                                   _mm_loadu_si128(reinterpret_cast<const __m128i*>(b)));
  const __m128i hi = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + 16)),
                                   _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + 16)));
  // Each byte holds at most 8 + 8, so the sum of both halves fits in a byte.
  const __m128i bytes = _mm_add_epi8(detail::popcount_bytes(lo), detail::popcount_bytes(hi));
  const __m128i sums = _mm_sad_epu8(bytes, _mm_setzero_si128());
  return _mm_cvtsi128_si32(sums) + _mm_extract_epi16(sums, 4);
#else
  int distance = 0;
  for (int i = 0; i < kDescriptorBytes; i += 8) {
    std::uint64_t x, y;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    distance += __builtin_popcountll(x ^ y);
  }
  return distance;
#endif
}

}  // namespace sbaslam::match
