// Software prefetch of a row that a sweep will read from memory a few rows later, so that its
// loads overlap the arithmetic of the rows before it (the hardware prefetchers of some CPUs do not
// run far enough ahead of a row-by-row stencil sweep; docs/performance.md has the measurements).
// One prefetch (into L1, for reading) per cache line; prefetches never fault, and no value read
// depends on them.
#pragma once

#include <cstddef>

namespace morphogen {

// Sweeps prefetch where a rank's state is at least this large (out of the per-core caches; in
// cache the prefetches only cost instructions), this many rows ahead.
constexpr double kPrefetchMinBytes = 8.0 * 1024 * 1024;
constexpr int kPrefetchRowsAhead = 2;

inline void prefetch_doubles(const double* p, std::ptrdiff_t n) {
  const char* c = reinterpret_cast<const char*>(p);
  const std::ptrdiff_t bytes = n * static_cast<std::ptrdiff_t>(sizeof(double));
  for (std::ptrdiff_t b = 0; b < bytes; b += 64)
    __builtin_prefetch(c + b, 0, 3);
}

} // namespace morphogen
