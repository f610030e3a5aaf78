// Fused explicit Euler sweep over one row of cells (pure kernel: no PETSc, MPI, allocation).
//
// The Laplacian is given in row form (grid/stencil.hpp, RowStencil): NR grid rows
// (row 0 is the cell's own row), each with three x-taps w[r][0..2] for x offsets -1, 0, +1.
// For each cell i of the row and each species s:
//   out_s = max( u_s + dt R_s(u; p) + sum_r sum_c W_s[r][c] u_s,r[i+c-1],  floor_s )
// with the taps scaled once per call, W_s[r][c] = (dt D_s) w[r][c] (the Euler step
// u + dt (D lap + R) with dt D folded into the weights: one multiply-add per cell and species
// fewer). Evaluated as fixed fused multiply-adds (std::fma): the sum starts at
// fma(dt, R_s, u_s), row 0's taps are fused into it left to right, box rows' taps are fused
// among themselves and then added, star rows' one tap is fused in; the same for every cell
// wherever it lies in a row: the project is compiled without FMA contraction (CMakeLists.txt),
// which could otherwise pair the operations differently in a loop's vector body and its
// remainder.
// Star stencils (5pt, 7pt: Box = false) use only the centre tap of rows r > 0; box stencils
// (9pt) use all three. One pointer per (species, row) keeps the live registers low (the x
// neighbours are the same pointer at i -+ 1). floor_s is 0 when negative concentrations are
// clamped and -inf otherwise; a row whose floors are all -inf takes an instantiation without
// the max (Clamp = false: the same values, max(v, -inf) = v, NaN kept). Each parameter q is a
// scalar (kept in a register: pconst[q]) or a row of per-cell values (prow[q]), as the bits of
// the compile-time mask PR say (ParamRows: bit q set, a row; the same value either way, so the
// same bits): a field-mode run whose other parameters are constant reads no row for those (each
// row read is one more load stream per cell in a kernel bounded by its loads). The
// loop over i carries `GCC ivdep` (rows never alias); the model's rates() inline into it and GCC
// vectorises it (configure with -DMORPHOGEN_VEC_REPORT=ON to see "loop vectorized" for this file).
// (`omp simd` is not used: GCC 12 turns the small per-cell arrays into "simd arrays" and then
// refuses to vectorise.) Wide = true only names a second instantiation, compiled with 512-bit
// vectors (integrators/kernels/<model>_wide.cpp; the same arithmetic per cell, so bitwise the
// same results): the explicit integrator picks it per sweep (-explicit_vector_width).
// The isotropic box stencils (2-D 9pt: 3 rows; 3-D 19pt, 27pt: 9 rows) take the weight-class
// path explicit_row_box_classes when ExplicitRow::wclass is set (the drivers set it; a
// different summation order, stated there); the tap loop serves a box stencil without that
// form (a 9-row one slowly: GCC does not unroll its loop over 9 rows, so it does not vectorise
// it).
#pragma once

#include "core/prefetch.hpp"
#include "fields/clamp_kernel.hpp"
#include "integrators/box_row_kernel.hpp"

#include <cmath>

namespace morphogen {

struct ExplicitRow {
  int n = 0;                           // cells in the row
  const double* const* src = nullptr;  // [nspecies * nrows]: src[s*NR+r] = row r of species s
  const double* w = nullptr;           // [nrows * 3] x-taps per row (include 1/h^2)
  const double* D = nullptr;           // [nspecies] diffusion coefficients
  const double* floor = nullptr;       // [nspecies] lower bound (0 or -inf)
  const double* const* prow = nullptr; // [nparams] per-cell parameter rows (field mode)
  const double* pconst = nullptr;      // [nparams] parameter scalars (scalar mode)
  double dt = 0;
  double* const* dst = nullptr;       // [nspecies] output rows
  const double* const* div = nullptr; // [nspecies] precomputed diffusion rows (general path)
  // Box stencils only: the weights by class (grid/stencil.hpp, BoxClasses: centre, face, edge,
  // corner) with src in class order, or null for the general tap form of w.
  const double* wclass = nullptr;
  // Consecutive rows in one call: row j reads src[q] + j src_stride and writes
  // dst[s] + j dst_stride. Only explicit_row with scalar parameters reads it (the other
  // kernels sweep one row; callers set rows = 1 for them).
  int rows = 1;
  long src_stride = 0, dst_stride = 0;
  // Software prefetch (box stencils by class, single-row calls): when nonzero, the kernel
  // prefetches each species' centre row prefetch_ahead cells past the cells it computes, one
  // prefetch per cache line, spread over its arithmetic (kernel_prefetch: per block of 8 cells,
  // per chunk). The tap loop ignores it (its callers prefetch the row before the call). Reads
  // nothing, so changes no result.
  long prefetch_ahead = 0;
};

// Cells per prefetch: one 64-byte cache line.
constexpr int kCellsPerLine = 8;

// One prefetch (into L1, for reading) of each species' centre row rows[s], `ahead` cells past
// cell i, for cells i .. i + m - 1 (core/prefetch.hpp: one per cache line). Prefetches never
// fault; no value read depends on them.
template <int NS>
inline void kernel_prefetch(const double* __restrict__ const* rows, long i, long ahead,
                            int m = kCellsPerLine) {
  for (int s = 0; s < NS; ++s)
    prefetch_doubles(rows[s] + i + ahead, m);
}

// The box stencils by weight class (ExplicitRow::wclass set), rows in class order: 3-D (19pt,
// 27pt, NR = 9) src[s*9] the centre row, src[s*9 + 1..4] the face rows, src[s*9 + 5..8] the
// corner rows; 2-D (9pt, NR = 3) src[s*3] the centre row, src[s*3 + 1..2] the face rows. Per
// chunk of up to kBoxChunk cells, first d of box_row_diffusion (box_row_kernel.hpp: lane
// shifts, no loads at x -+ 1) into a stack buffer, with the class weights scaled by dt D_s,
// then per cell (2-D: the blocks of box_classes_blocks, d in registers, where the row allows)
//   out_s = max( fma(dt, R_s, u_s) + d_s(i),  floor_s ).
// Per cell and species in 3-D: 9 loads, 6 adds and 4-6 multiply-adds for the profiles, 2 adds
// for the taps, instead of 27 loads and 27 multiply-adds; in 2-D 3 loads, 1 add, 4 multiply-adds
// and 2 adds instead of 9 loads (6 of them across cache lines) and 9 multiply-adds. Each value is
// one fixed expression of the cell's neighbours, so neither the chunks nor the rank decomposition
// change a bit.
constexpr int kBoxChunk = 128;

// True when some species has a finite floor (the max of the update is needed).
inline bool any_floor(const double* floor, int ns) {
  for (int s = 0; s < ns; ++s)
    if (floor[s] != -HUGE_VAL) return true;
  return false;
}

// Which parameters a row kernel reads as rows of per-cell values (bit q: parameter q), the
// others as the scalars pconst. A distinct type, so that no bool converts into it.
enum class ParamRows : unsigned {};
constexpr ParamRows kScalarParams{0u};
constexpr ParamRows kAllParamRows{~0u};
constexpr bool param_is_row(ParamRows m, int q) {
  return (static_cast<unsigned>(m) >> q & 1u) != 0;
}
constexpr bool any_param_row(ParamRows m) {
  return static_cast<unsigned>(m) != 0;
}

// The kernel's NP parameters: the scalars pc (pconst is set in every mode) and, where PR has a
// row, every row pointer (the kernel reads those of PR; setting all of them keeps GCC's loop
// from spilling pointers: 15 % faster than setting only those read, for a mask with a scalar
// among rows, in a harness of the Turing 5pt row).
template <ParamRows PR, int NP, int NPA>
inline void load_params(const ExplicitRow& a, const double* __restrict__ (&prow)[NPA],
                        double (&pc)[NPA]) {
  for (int q = 0; q < NP; ++q) {
    pc[q] = a.pconst[q];
    if constexpr (any_param_row(PR)) prow[q] = a.prow[q];
  }
}

// Cell i of a box-class row: out_s = max(fma(dt, R_s, u_s) + d_s, floor_s), d_s = d[s dstride].
template <class M, ParamRows PR, bool Clamp, int NP>
inline void box_class_cell(int i, const double* d, int dstride,
                           const double* __restrict__ const* src, double* __restrict__ const* dst,
                           const double* __restrict__ const* prow, const double* pc,
                           const double* floor, double dt) {
  constexpr int NS = M::nspecies;
  double u[NS], r[NS], p[NP > 0 ? NP : 1];
  for (int q = 0; q < NP; ++q)
    p[q] = param_is_row(PR, q) ? prow[q][i] : pc[q];
  for (int s = 0; s < NS; ++s)
    u[s] = src[s][i];
  M::rates(u, p, r);
  for (int s = 0; s < NS; ++s) {
    const double v = std::fma(dt, r[s], u[s]) + d[s * dstride];
    dst[s][i] = Clamp ? clamp_to_floor(v, floor[s]) : v;
  }
}

#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
// The 2-D 9-point rows (NR = 3) from x0 in blocks of L = 8 (Wide) or 4 lanes while the lane
// shifts' loads stay within the rows (x + 2 L - 2 <= n): per block each species' d
// (box_row_diffusion's lane-shift expressions) stays in registers and the reaction runs over
// the block's lanes (one vector each: `unroll 1` keeps GCC from unrolling the 4-lane loop
// before it vectorises it), with no buffer pass between them: 46 instead of about 60
// instructions per 8 cells and species pair at 512 bits. Returns the number of cells done;
// the same expressions per cell as the chunks, so the same bits.
template <class M, int NR, ParamRows PR, bool Corners, bool Clamp, bool Wide, int NP, bool Prefetch>
inline int box_classes_blocks(const double* const* rows, const double (&wc)[M::nspecies][4],
                              const double* __restrict__ const* src,
                              double* __restrict__ const* dst,
                              const double* __restrict__ const* prow, const double* pc,
                              const double* floor, double dt, int x0, int n, long ahead) {
  constexpr int NS = M::nspecies;
  constexpr int L = Wide ? 8 : 4;
  using B = BoxLanes<L>;
  using V = typename B::V;
  if (x0 + 2 * L - 2 > n) return 0;
  V wv[NS][4], p0[NS], q0[NS];
  for (int s = 0; s < NS; ++s) {
    for (int c = 0; c < 4; ++c)
      wv[s][c] = B::splat(wc[s][c]);
    B::template profile<NR, Corners>(rows + s * NR, wv[s], x0 - 1, p0[s], q0[s]);
  }
  int t = 0;
  for (; x0 + t + 2 * L - 2 <= n; t += L) {
    alignas(64) double dl[NS][L];
    if (Prefetch && (L == kCellsPerLine || t % kCellsPerLine == 0))
      kernel_prefetch<NS>(src, x0 + t, ahead);
    for (int s = 0; s < NS; ++s) {
      V p1, q1;
      B::template profile<NR, Corners>(rows + s * NR, wv[s], x0 + t + L - 1, p1, q1);
      const V dv = B::template shift<1>(q0[s], q1) + (p0[s] + B::template shift<2>(p0[s], p1));
      *reinterpret_cast<V*>(dl[s]) = dv;
      p0[s] = p1;
      q0[s] = q1;
    }
#pragma GCC ivdep
#pragma GCC unroll 1
    for (int l = 0; l < L; ++l)
      box_class_cell<M, PR, Clamp, NP>(x0 + t + l, &dl[0][l], L, src, dst, prow, pc, floor, dt);
  }
  return t;
}
#endif

template <class M, int NR, ParamRows PR, bool Corners, bool Clamp, bool Wide = false>
inline void explicit_row_box_classes(const ExplicitRow& a) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams;
  const double* rows[NS * NR];        // all rows, read by box_row_diffusion
  const double* __restrict__ src[NS]; // the centre rows
  double* __restrict__ dst[NS];
  double wc[NS][4], floor[NS], pc[NP > 0 ? NP : 1];
  const double* __restrict__ prow[NP > 0 ? NP : 1];
  const double dt = a.dt;
  for (int q = 0; q < NS * NR; ++q)
    rows[q] = a.src[q];
  for (int s = 0; s < NS; ++s) {
    src[s] = a.src[s * NR];
    dst[s] = a.dst[s];
    for (int c = 0; c < 4; ++c)
      wc[s][c] = (dt * a.D[s]) * a.wclass[c];
    floor[s] = a.floor[s];
  }
  load_params<PR, NP>(a, prow, pc);
  const int n = a.n;
  alignas(64) double dbuf[NS][kBoxChunk];
  auto chunk = [&](int i0, int m) { // cells i0 .. i0 + m - 1, m <= kBoxChunk
    if (a.prefetch_ahead != 0) kernel_prefetch<NS>(src, i0, a.prefetch_ahead, m);
    for (int s = 0; s < NS; ++s)
      box_row_diffusion<NR, Corners, Wide>(rows + s * NR, wc[s], i0, m, n, dbuf[s]);
#pragma GCC ivdep
    for (int x = 0; x < m; ++x)
      box_class_cell<M, PR, Clamp, NP>(i0 + x, &dbuf[0][x], kBoxChunk, src, dst, prow, pc, floor,
                                       dt);
  };
  const int nrows = any_param_row(PR) ? 1 : a.rows;
  for (int j = 0; j < nrows; ++j) {
    // Chunks start where the rows' vectors are aligned (where all rows share one alignment, as
    // a fused pass's ring rows do), after a first chunk of the cells before it.
    const int a0 = box_row_aligned_start<Wide>(rows, NS * NR, n);
    if (a0 > 0) chunk(0, a0);
    int b0 = a0;
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__)
    if constexpr (NR == 3) { // (the 9-row blocks measured slower at 512 bits: registers)
      const long ahead = a.prefetch_ahead; // a separate loop: no test per block without it
      b0 += ahead != 0 ? box_classes_blocks<M, NR, PR, Corners, Clamp, Wide, NP, true>(
                             rows, wc, src, dst, prow, pc, floor, dt, a0, n, ahead)
                       : box_classes_blocks<M, NR, PR, Corners, Clamp, Wide, NP, false>(
                             rows, wc, src, dst, prow, pc, floor, dt, a0, n, 0);
    }
#endif
    for (int i0 = b0; i0 < n; i0 += kBoxChunk)
      chunk(i0, n - i0 < kBoxChunk ? n - i0 : kBoxChunk);
    for (int q = 0; q < NS * NR; ++q)
      rows[q] += a.src_stride;
    for (int s = 0; s < NS; ++s) {
      src[s] += a.src_stride;
      dst[s] += a.dst_stride;
    }
  }
}

template <class M, int NR, bool Box, ParamRows PR, bool Clamp, bool Wide = false>
inline void explicit_row_taps(const ExplicitRow& a) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams;
  const double* __restrict__ src[NS * NR];
  double* __restrict__ dst[NS];
  double w[NS][NR][3], floor[NS], pc[NP > 0 ? NP : 1];
  const double* __restrict__ prow[NP > 0 ? NP : 1];
  const double dt = a.dt;
  for (int q = 0; q < NS * NR; ++q)
    src[q] = a.src[q];
  for (int s = 0; s < NS; ++s) {
    for (int r = 0; r < NR; ++r)
      for (int c = 0; c < 3; ++c)
        w[s][r][c] = (dt * a.D[s]) * a.w[3 * r + c];
    dst[s] = a.dst[s];
    floor[s] = a.floor[s];
  }
  load_params<PR, NP>(a, prow, pc);
  const int n = a.n;
  const int rows = any_param_row(PR) ? 1 : a.rows;
  for (int j = 0; j < rows; ++j) {
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
      double u[NS], r[NS], p[NP > 0 ? NP : 1];
      for (int q = 0; q < NP; ++q)
        p[q] = param_is_row(PR, q) ? prow[q][i] : pc[q];
      for (int s = 0; s < NS; ++s)
        u[s] = src[s * NR][i];
      M::rates(u, p, r);
      for (int s = 0; s < NS; ++s) {
        const double* __restrict__ c = src[s * NR];
        const double(&ws)[NR][3] = w[s];
        double v = std::fma(dt, r[s], u[s]);
        v = std::fma(ws[0][2], c[i + 1], std::fma(ws[0][1], u[s], std::fma(ws[0][0], c[i - 1], v)));
        for (int q = 1; q < NR; ++q) {
          const double* __restrict__ row = src[s * NR + q];
          if constexpr (Box) // the row's three taps, then added (independent chains per row)
            v += std::fma(ws[q][2], row[i + 1], std::fma(ws[q][1], row[i], ws[q][0] * row[i - 1]));
          else
            v = std::fma(ws[q][1], row[i], v);
        }
        dst[s][i] = Clamp ? clamp_to_floor(v, floor[s]) : v;
      }
    }
    for (int q = 0; q < NS * NR; ++q)
      src[q] += a.src_stride;
    for (int s = 0; s < NS; ++s)
      dst[s] += a.dst_stride;
  }
}

template <class M, int NR, bool Box, ParamRows PR, bool Wide = false>
inline void explicit_row(const ExplicitRow& a) {
  const bool clamp = any_floor(a.floor, M::nspecies);
  if constexpr (NR == 3 && Box) { // 2-D: no corner class (w[3] is 0)
    if (a.wclass) {
      if (clamp)
        explicit_row_box_classes<M, 3, PR, false, true, Wide>(a);
      else
        explicit_row_box_classes<M, 3, PR, false, false, Wide>(a);
      return;
    }
  }
  if constexpr (NR == 9 && Box) {
    if (a.wclass) {
      const bool corners = a.wclass[3] != 0.0;
      if (clamp && corners)
        explicit_row_box_classes<M, 9, PR, true, true, Wide>(a);
      else if (clamp)
        explicit_row_box_classes<M, 9, PR, false, true, Wide>(a);
      else if (corners)
        explicit_row_box_classes<M, 9, PR, true, false, Wide>(a);
      else
        explicit_row_box_classes<M, 9, PR, false, false, Wide>(a);
      return;
    }
  }
  if (clamp)
    explicit_row_taps<M, NR, Box, PR, true, Wide>(a);
  else
    explicit_row_taps<M, NR, Box, PR, false, Wide>(a);
}

// The general path's update of one row: the diffusion terms were computed into div[s] (a row
// buffer, operators/diffusion_operator.hpp) and are added with the reaction:
//   out_s = max( u_s + dt (div_s + R_s(u; p)),  floor_s )
// src[s] is species s's row (one row per species, no neighbours read). explicit_row_pre_of
// takes a model object m (rates(u, p, r) may carry state) with NS species and np <= NPMax
// parameters; explicit_row_pre<M, FieldParams> is it for a model type.
template <int NS, int NPMax, bool FieldParams, class Model>
inline void explicit_row_pre_of(const Model& m, int np, const ExplicitRow& a) {
  constexpr int NPA = NPMax > 0 ? NPMax : 1;
  const double* __restrict__ src[NS];
  const double* __restrict__ div[NS];
  double* __restrict__ dst[NS];
  double floor[NS], pc[NPA];
  const double* __restrict__ prow[NPA];
  for (int s = 0; s < NS; ++s) {
    src[s] = a.src[s];
    div[s] = a.div[s];
    dst[s] = a.dst[s];
    floor[s] = a.floor[s];
  }
  for (int q = 0; q < np; ++q) {
    if constexpr (FieldParams)
      prow[q] = a.prow[q];
    else
      pc[q] = a.pconst[q];
  }
  const double dt = a.dt;
  const int n = a.n;
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) {
    double u[NS], r[NS], p[NPA];
    for (int q = 0; q < np; ++q) {
      if constexpr (FieldParams)
        p[q] = prow[q][i];
      else
        p[q] = pc[q];
    }
    for (int s = 0; s < NS; ++s)
      u[s] = src[s][i];
    m.rates(u, p, r);
    for (int s = 0; s < NS; ++s) {
      const double v = std::fma(dt, div[s][i] + r[s], u[s]);
      dst[s][i] = clamp_to_floor(v, floor[s]);
    }
  }
}

// The same update with the reaction rates of the row given (r[s][i] = R_s at cell i, computed
// for the whole row beforehand, e.g. by ModelInfo::rates_row): the arithmetic of
// explicit_row_pre_of, so the results are bitwise the same for bitwise equal rates.
template <int NS> inline void explicit_row_pre_rates(const ExplicitRow& a, const double* const* r) {
  const double dt = a.dt;
  const int n = a.n;
  for (int s = 0; s < NS; ++s) {
    const double* __restrict__ u = a.src[s];
    const double* __restrict__ div = a.div[s];
    const double* __restrict__ rs = r[s];
    double* __restrict__ dst = a.dst[s];
    const double floor = a.floor[s];
#pragma GCC ivdep
    for (int i = 0; i < n; ++i) {
      const double v = std::fma(dt, div[i] + rs[i], u[i]);
      dst[i] = clamp_to_floor(v, floor);
    }
  }
}

template <class M, bool FieldParams> inline void explicit_row_pre(const ExplicitRow& a) {
  explicit_row_pre_of<M::nspecies, M::nparams, FieldParams>(M{}, M::nparams, a);
}

} // namespace morphogen
