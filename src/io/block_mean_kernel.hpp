// Block means of a 2-D field for quick-look images, exact in any summation order.
//
// A field of nx x ny cells shown in at most max_size pixels per axis is reduced by an integer
// factor f = ceil(max(nx, ny) / max_size) (1: no reduction); pixel (I, J) is the mean of the
// cells i in [f I, min(f I + f, nx)), j likewise (edge blocks hold fewer cells).
// To make the mean independent of how the cells are split across ranks, every finite value v is
// first quantised against the field's global finite range [lo, hi]:
//   q(v) = llround((v - lo) * scale),  scale = 2^B / (hi - lo)  (0 when hi <= lo),
// with B = min(40, 62 - ceil(log2(f^2))) so that f^2 quanta cannot overflow an int64; the
// integer sums are associative, and the mean is lo + (sum q / count) / scale: within
// (hi - lo) 2^-(B+1) of the exact block mean (2^-41 of the range at f <= 4), far below one step
// of a 16-bit grey level. A block holding any non-finite value is NaN.
// Pure host functions (no MPI, no allocation): the caller owns the arrays.
#pragma once

#include <cmath>
#include <cstdint>

namespace morphogen::io {

struct BlockMeanPlan {
  long long nx = 0, ny = 0; // field cells
  long long f = 1;          // block side in cells
  long long w = 0, h = 0;   // image pixels: ceil(nx / f) x ceil(ny / f)
  double lo = 0, scale = 0; // quantisation (see above)
};

// One block's accumulators: the quantised sum, the finite count and the non-finite count.
struct BlockSum {
  std::int64_t q = 0, count = 0, bad = 0;
};

// The reduction factor: 1 when max_size == 0 (off) or the field already fits.
inline long long block_factor(long long nx, long long ny, long long max_size) {
  const long long n = nx > ny ? nx : ny;
  if (max_size <= 0 || n <= max_size) return 1;
  return (n + max_size - 1) / max_size;
}

// The plan for a field with global finite range [lo, hi] (lo > hi: no finite value).
inline BlockMeanPlan block_mean_plan(long long nx, long long ny, long long max_size, double lo,
                                     double hi) {
  BlockMeanPlan p;
  p.nx = nx;
  p.ny = ny;
  p.f = block_factor(nx, ny, max_size);
  p.w = (nx + p.f - 1) / p.f;
  p.h = (ny + p.f - 1) / p.f;
  int bits = 0; // ceil(log2(f^2))
  while ((1LL << bits) < p.f * p.f)
    ++bits;
  const int B = 62 - bits < 40 ? 62 - bits : 40;
  p.lo = lo;
  p.scale = hi > lo ? std::ldexp(1.0, B) / (hi - lo) : 0.0;
  return p;
}

// Adds the cells of one row segment (global row j, cells i0 .. i0 + n - 1, values row[0..n))
// into the blocks of a rectangle of blocks whose lower-left block is (bx0, by0) and which is
// bw blocks wide: block (I, J) is sums[(I - bx0) + bw (J - by0)].
inline void add_row_to_blocks(const BlockMeanPlan& p, long long j, long long i0, long long n,
                              const double* row, long long bx0, long long by0, long long bw,
                              BlockSum* sums) {
  BlockSum* line = sums + bw * (j / p.f - by0);
  for (long long c = 0; c < n; ++c) {
    const double v = row[c];
    BlockSum& b = line[(i0 + c) / p.f - bx0];
    if (std::isfinite(v)) {
      b.q += std::llround((v - p.lo) * p.scale);
      ++b.count;
    } else {
      ++b.bad;
    }
  }
}

// The mean of one block (NaN if it held a non-finite value or no cell).
inline double block_mean(const BlockMeanPlan& p, const BlockSum& b) {
  if (b.bad > 0 || b.count == 0) return NAN;
  if (p.scale == 0.0) return p.lo;
  return p.lo + static_cast<double>(b.q) / static_cast<double>(b.count) / p.scale;
}

} // namespace morphogen::io
