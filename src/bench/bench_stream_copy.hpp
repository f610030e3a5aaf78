// For the access-pattern section (bench_access_pattern.cpp; measured slower than memcpy for the
// solver's ring commit, so the solver does not use it):
// dst[0 .. n) = src[0 .. n) with non-temporal (streaming) stores where the CPU has them (x86-64:
// 512-, 256- or 128-bit): the destination's cache lines go to memory without being read first
// or kept in the caches. The cells before dst's first 64-byte boundary (and after its last)
// take ordinary stores. A caller whose dst another core or process reads fences first
// (stream_fence). Values are copied bit for bit either way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__AVX512F__) || defined(__AVX__) || defined(__SSE2__)
#include <immintrin.h>
#define MORPHOGEN_STREAM_STORES 1
#endif

namespace morphogen {

// The form stream_copy takes in this build: "512-bit", "256-bit", "128-bit" or "memcpy".
constexpr const char* stream_copy_kind() {
#if defined(__AVX512F__)
  return "512-bit";
#elif defined(__AVX__)
  return "256-bit";
#elif defined(__SSE2__)
  return "128-bit";
#else
  return "memcpy";
#endif
}

inline void stream_copy(double* dst, const double* src, std::ptrdiff_t n) {
#if defined(MORPHOGEN_STREAM_STORES)
  std::ptrdiff_t i = 0;
  while (i < n && (reinterpret_cast<std::uintptr_t>(dst + i) & 63u) != 0) {
    dst[i] = src[i];
    ++i;
  }
#if defined(__AVX512F__)
  for (; i + 8 <= n; i += 8)
    _mm512_stream_pd(dst + i, _mm512_loadu_pd(src + i));
#elif defined(__AVX__)
  for (; i + 4 <= n; i += 4)
    _mm256_stream_pd(dst + i, _mm256_loadu_pd(src + i));
#else
  for (; i + 2 <= n; i += 2)
    _mm_stream_pd(dst + i, _mm_loadu_pd(src + i));
#endif
  for (; i < n; ++i)
    dst[i] = src[i];
#else
  std::memcpy(dst, src, static_cast<size_t>(n) * sizeof(double));
#endif
}

// Orders the streaming stores before everything after it (other cores, MPI).
inline void stream_fence() {
#if defined(MORPHOGEN_STREAM_STORES)
  _mm_sfence();
#endif
}

} // namespace morphogen
