// The W lanes of a row chunk for the per-cell reaction kernels (pure: no PETSc, MPI,
// allocation): structure-of-arrays inputs and state, and their loader. Every lane of a chunk runs
// the same vector code, also past the row's end (those lanes repeat its last cell), so a cell's
// result does not depend on where in a row, or on which rank, it lies.
#pragma once

#include "fields/clamp_kernel.hpp"

#include <cfloat>
#include <cmath>

// The lane loops run on 512-bit vectors where the target has them (GCC; the rest of the build
// prefers 256-bit ones).
#if defined(__GNUC__) && !defined(__clang__) && defined(__AVX512F__)
#define MG_LANES_WIDE __attribute__((target("prefer-vector-width=512")))
#else
#define MG_LANES_WIDE
#endif
// A lane loop forced inline into its caller's chunk loop (GCC 12 left the Newton step an
// out-of-line call; inlined, the lockstep row is about 7 % faster).
#if defined(__GNUC__)
#define MG_LANES_INLINE inline __attribute__((always_inline))
#else
#define MG_LANES_INLINE inline
#endif

namespace morphogen::detail {

inline bool finite_d(double x) {
  return std::fabs(x) <= DBL_MAX;
} // false for NaN and inf

// 1.0 where x is finite, 0.0 for NaN and inf (a select, so that the lane loops vectorise).
inline double finite_mask(double x) {
  return std::fabs(x) <= DBL_MAX ? 1.0 : 0.0;
}

// Cells [i0, i0 + W) of the output rows from a full chunk's values v, clamped to floor.
template <int NS, int W>
inline void store_clamped(const double (&v)[NS][W], int i0, const double* floor,
                          double* const* out) {
#pragma GCC unroll 16
  for (int s = 0; s < NS; ++s) {
    const double f = floor[s];
    double* o = out[s] + i0;
#pragma GCC ivdep
    for (int l = 0; l < W; ++l)
      o[l] = clamp_to_floor(v[s][l], f);
  }
}

// The W lanes of one chunk (structure of arrays): inputs, iterate and per-lane state (0/1
// flags as doubles so that every select vectorises: done, converged; act, still iterating, i.e.
// neither converged nor left to the per-cell solver).
template <int NS, int NP, int W> struct LockstepLanes {
  double u[NS][W], s0[NS][W], s1[NS][W], p[NP][W];
  double base[NS][W], v[NS][W], F[NS][W], unorm[W], res[W], its[W], done[W], act[W];
};

// Lane l of a per-lane state x (u or v) as a per-cell array.
template <int NS, int W> inline void lane_state(const double (&x)[NS][W], int l, double* xc) {
#pragma GCC unroll 16
  for (int s = 0; s < NS; ++s)
    xc[s] = x[s][l];
}

// Lane l's parameters: its row of the per-lane array where they vary (FieldParams), else the
// constants themselves (no per-lane loads).
template <bool FieldParams, int NP, int W>
inline void lane_params(const double (&p)[NP][W], const double* pconst, int l, double* pc) {
#pragma GCC unroll 16
  for (int q = 0; q < NP; ++q)
    pc[q] = FieldParams ? p[q][l] : pconst[q];
}

// r + s where the row has sources (Src), else r: adding a source-free row's zeros would change
// nothing but the sign of a zero.
template <bool Src> inline double plus_source(double r, double s) {
  if constexpr (Src)
    return r + s;
  else
    return r;
}

// Loads cells [i0, i0 + w) of the row into the lanes; lanes past the row repeat its last cell.
// A full chunk (w = W) is plain vectorised copies.
template <int NS, int NP, int W, bool FieldParams>
inline void lockstep_load(LockstepLanes<NS, NP, W>& L, int i0, int w, int np,
                          const double* const* u, const double* const* prow, const double* pconst,
                          const double* const* S0, const double* const* S1) {
  for (int s = 0; s < NS; ++s) {
    const double *us = u[s] + i0, *a = S0 ? S0[s] + i0 : nullptr, *b = S1 ? S1[s] + i0 : nullptr;
    if (w == W) {
#pragma GCC ivdep
      for (int l = 0; l < W; ++l)
        L.u[s][l] = us[l];
    } else
      for (int l = 0; l < W; ++l)
        L.u[s][l] = us[l < w ? l : w - 1];
    for (int l = 0; l < W; ++l)
      L.s0[s][l] = a ? a[l < w ? l : w - 1] : 0.0;
    for (int l = 0; l < W; ++l)
      L.s1[s][l] = b ? b[l < w ? l : w - 1] : 0.0;
  }
  for (int q = 0; q < np; ++q)
    for (int l = 0; l < W; ++l)
      L.p[q][l] = FieldParams ? prow[q][i0 + (l < w ? l : w - 1)] : pconst[q];
}

} // namespace morphogen::detail
