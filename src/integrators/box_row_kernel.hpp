// The diffusion part of the box stencils' weight-class kernel (explicit_kernel.hpp,
// explicit_row_box_classes) along one row (pure kernel: no PETSc, MPI, allocation): NR = 9 rows
// (3-D: 19pt, 27pt) or NR = 3 rows (2-D: 9pt).
#pragma once

#include <cmath>
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__) &&                            \
    (defined(__FMA__) || defined(__AVX512F__))
#include <immintrin.h>
#endif

namespace morphogen {

// For x = x0 .. x0 + len - 1 of one species' rows in class order (w: centre, face, edge,
// corner weight), A being the centre row:
//   B = (f1 + f2) + (f3 + f4)        (the 4 face rows; 2-D: B = f1 + f2)
//   C = (k1 + k2) + (k3 + k4)        (the 4 corner rows; 2-D: none)
//   q(x) = (w_c A + w_f B) + w_e C   (the taps at dx = 0; 2-D: without w_e C)
//   p(x) = (w_f A + w_e B) + w_k C   (the taps at dx = -1, +1; w_k C left out if !Corners or 2-D)
//   d(x) = q(x) + (p(x - 1) + p(x + 1))
// (each sum of products a chain of std::fma from the left). In 2-D the taps with two non-zero
// offsets, the 9pt stencil's corners, are the "edge" class. box_row_profile evaluates p and q
// at one x; box_row_diffusion_cells d cell by cell (each profile once, the last three kept).
template <int NR, bool Corners>
inline void box_row_profile(const double* const* rows, const double* w, int x, double& p,
                            double& q) {
  static_assert(NR == 3 || NR == 9, "box rows: 3 (2-D) or 9 (3-D)");
  const double A = rows[0][x];
  if constexpr (NR == 3) {
    const double B = rows[1][x] + rows[2][x];
    q = std::fma(w[1], B, w[0] * A);
    p = std::fma(w[2], B, w[1] * A);
  } else {
    const double B = (rows[1][x] + rows[2][x]) + (rows[3][x] + rows[4][x]);
    const double C = (rows[5][x] + rows[6][x]) + (rows[7][x] + rows[8][x]);
    q = std::fma(w[2], C, std::fma(w[1], B, w[0] * A));
    p = Corners ? std::fma(w[3], C, std::fma(w[2], B, w[1] * A)) : std::fma(w[2], B, w[1] * A);
  }
}

template <int NR, bool Corners>
inline void box_row_diffusion_cells(const double* const* rows, const double* w, int x0, int len,
                                    double* __restrict__ d) {
  if (len <= 0) return;
  double pl, ql, pc, qc, pr, qr;
  box_row_profile<NR, Corners>(rows, w, x0 - 1, pl, ql);
  box_row_profile<NR, Corners>(rows, w, x0, pc, qc);
  for (int t = 0; t < len; ++t) {
    box_row_profile<NR, Corners>(rows, w, x0 + t + 1, pr, qr);
    d[t] = qc + (pl + pr);
    pl = pc;
    pc = pr;
    qc = qr;
  }
}

#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
// GCC's vector extensions: d by blocks of L = 8 (Wide: 512-bit) or 4 lanes, each profile once
// per cell, its x-neighbours from the registers of the adjacent block (lane shifts) instead of
// loads at x -+ 1 (which cross cache lines) and a buffer of p and q: the same operations per
// lane, so the same bits as box_row_diffusion_cells.
typedef double box_v8 __attribute__((vector_size(64)));
typedef long long box_i8 __attribute__((vector_size(64)));
typedef double box_u8 __attribute__((vector_size(64), aligned(8), may_alias)); // unaligned
typedef double box_v4 __attribute__((vector_size(32)));
typedef long long box_i4 __attribute__((vector_size(32)));
typedef double box_u4 __attribute__((vector_size(32), aligned(8), may_alias));
template <int L> struct BoxLaneTypes;
template <> struct BoxLaneTypes<8> {
  using V = box_v8;
  using I = box_i8;
  using U = box_u8;
};
template <> struct BoxLaneTypes<4> {
  using V = box_v4;
  using I = box_i4;
  using U = box_u4;
};
template <int L> struct BoxLanes {
  using V = typename BoxLaneTypes<L>::V; // L doubles
  using I = typename BoxLaneTypes<L>::I; // lane indices of __builtin_shuffle
  using U = typename BoxLaneTypes<L>::U; // V at any 8-byte alignment
  static V load(const double* x) { return *reinterpret_cast<const U*>(x); }
  static V splat(double a) {
    V v;
    for (int l = 0; l < L; ++l)
      v[l] = a;
    return v;
  }
  // std::fma per lane: one vector instruction where the target has it (GCC does not always
  // turn the lane loop into one).
  static V fma(V a, V b, V c) {
#if defined(__AVX512F__)
    if constexpr (L == 8) return _mm512_fmadd_pd(a, b, c);
#endif
#if defined(__FMA__)
    if constexpr (L == 4) return _mm256_fmadd_pd(a, b, c);
#endif
    V r;
    for (int l = 0; l < L; ++l)
      r[l] = std::fma(a[l], b[l], c[l]);
    return r;
  }
  // Lanes k .. k + L - 1 of the concatenation (a, b). With AVX-512 one valignq, which leaves
  // both inputs in their registers (GCC's shuffle picks vpermt2pd, which overwrites one, and
  // then copies registers around it). (The all-lanes masked form: GCC 12 warns about the
  // undefined source operand of the unmasked one.)
  template <int K> static V shift(V a, V b) {
#if defined(__AVX512F__)
    if constexpr (L == 8) {
      const __m512i ai = _mm512_castpd_si512(a), bi = _mm512_castpd_si512(b);
      return _mm512_castsi512_pd(_mm512_mask_alignr_epi64(ai, 0xFF, bi, ai, K));
    }
#endif
#if defined(__AVX512VL__)
    if constexpr (L == 4) {
      const __m256i ai = _mm256_castpd_si256(a), bi = _mm256_castpd_si256(b);
      return _mm256_castsi256_pd(_mm256_mask_alignr_epi64(ai, 0xF, bi, ai, K));
    }
#endif
    if constexpr (L == 8)
      return __builtin_shuffle(a, b, I{K, K + 1, K + 2, K + 3, K + 4, K + 5, K + 6, K + 7});
    else
      return __builtin_shuffle(a, b, I{K, K + 1, K + 2, K + 3});
  }
  // Lanes 1 .. L - 1 of a, then lane L - 2 of b: q at x0 .. x0 + L - 1 from q at x0 - 1 and
  // x0 + 1.
  static V centre(V a, V b) {
    if constexpr (L == 8)
      return __builtin_shuffle(a, b, I{1, 2, 3, 4, 5, 6, 7, 14});
    else
      return __builtin_shuffle(a, b, I{1, 2, 3, 6});
  }
  template <int NR, bool Corners>
  static void profile(const double* const* rows, const V* w, int x, V& p, V& q) {
    const V A = load(rows[0] + x);
    if constexpr (NR == 3) {
      const V B = load(rows[1] + x) + load(rows[2] + x);
      q = fma(w[1], B, w[0] * A);
      p = fma(w[2], B, w[1] * A);
    } else {
      const V B = (load(rows[1] + x) + load(rows[2] + x)) + (load(rows[3] + x) + load(rows[4] + x));
      const V C = (load(rows[5] + x) + load(rows[6] + x)) + (load(rows[7] + x) + load(rows[8] + x));
      q = fma(w[2], C, fma(w[1], B, w[0] * A));
      p = Corners ? fma(w[3], C, fma(w[2], B, w[1] * A)) : fma(w[2], B, w[1] * A);
    }
  }
};
#endif

// The first x in [0, n) from which the lane-shift loop of box_row_diffusion, started there,
// loads whole aligned vectors (Wide: 64 bytes, a cache line; else 32) from each of the `count`
// rows (its loads start at x - 1), when all rows share their alignment; 0 otherwise. The cells
// before it are computed by the same expressions (no bit changes), by the cell loop.
template <bool Wide> inline int box_row_aligned_start(const double* const* rows, int count, int n) {
  constexpr unsigned long bytes = Wide ? 64 : 32;
  const unsigned long a = (reinterpret_cast<unsigned long>(rows[0]) - sizeof(double)) % bytes;
  if (a % sizeof(double) != 0) return 0;
  for (int q = 1; q < count; ++q)
    if ((reinterpret_cast<unsigned long>(rows[q]) - sizeof(double)) % bytes != a) return 0;
  const int x = static_cast<int>((bytes - a) % bytes / sizeof(double));
  return x < n ? x : 0;
}

// d(x) of the comment above for x = x0 .. x0 + len - 1 (into d[0 .. len - 1]), reading the rows
// at x0 - 1 .. max(x0 + len, min(xmax, x0 + len + 2 L - 2)): xmax is the last x the rows hold.
template <int NR, bool Corners, bool Wide = false>
inline void box_row_diffusion(const double* const* rows, const double* w, int x0, int len, int xmax,
                              double* __restrict__ d) {
  int t = 0;
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
  constexpr int L = Wide ? 8 : 4;
  using B = BoxLanes<L>;
  using V = typename B::V;
  if (len >= L) {
    const V wv[4] = {B::splat(w[0]), B::splat(w[1]), B::splat(w[2]), B::splat(w[3])};
    V p0, q0, p1, q1;
    B::template profile<NR, Corners>(rows, wv, x0 - 1, p0, q0); // x0 - 1 .. x0 + L - 2
    for (; t + L <= len && x0 + t + 2 * L - 2 <= xmax; t += L) {
      B::template profile<NR, Corners>(rows, wv, x0 + t + L - 1, p1, q1);
      const V dv = B::template shift<1>(q0, q1) + (p0 + B::template shift<2>(p0, p1));
      *reinterpret_cast<typename B::U*>(d + t) = dv;
      p0 = p1;
      q0 = q1;
    }
    while (t < len) { // the last blocks (the last one may overlap): profiles at x - 1 and x + 1
      const int b = t + L <= len ? t : len - L;
      V pl, ql, pr, qr;
      B::template profile<NR, Corners>(rows, wv, x0 + b - 1, pl, ql);
      B::template profile<NR, Corners>(rows, wv, x0 + b + 1, pr, qr);
      *reinterpret_cast<typename B::U*>(d + b) = B::centre(ql, qr) + (pl + pr);
      t = b + L;
    }
  }
#else
  (void)xmax;
#endif
  box_row_diffusion_cells<NR, Corners>(rows, w, x0 + t, len - t, d + t);
}

} // namespace morphogen
