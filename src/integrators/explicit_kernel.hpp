// Fused explicit Euler sweep over one row of cells (pure kernel: no PETSc, MPI, allocation).
//
// The Laplacian is given in row form (grid/stencil.hpp, RowStencil): NR grid rows
// (row 0 is the cell's own row), each with three x-taps w[r][0..2] for x offsets -1, 0, +1.
// For each cell i of the row and each species s:
//   lap_s = sum_r ( w[r][0] u_s,r[i-1] + w[r][1] u_s,r[i] + w[r][2] u_s,r[i+1] )
//   out_s = max( u_s + dt (D_s lap_s + R_s(u; p)),  floor_s )
// Star stencils (5pt, 7pt: Box = false) use only the centre tap of rows r > 0; box stencils
// (9pt) use all three. One pointer per (species, row) keeps the live registers low (the x
// neighbours are the same pointer at i -+ 1). floor_s is 0 when negative concentrations are
// clamped and -inf otherwise (branch-free). Parameters are scalars (FieldParams = false: kept
// in registers) or rows of per-cell values (FieldParams = true). The loop over i carries
// `GCC ivdep` (rows never alias); the model's rates() inline into it and GCC vectorises it
// (configure with -DMORPHOGEN_VEC_REPORT=ON to see "loop vectorized" for this file).
// (`omp simd` is not used: GCC 12 turns the small per-cell arrays into "simd arrays" and then
// refuses to vectorise.)
#pragma once

#include "fields/clamp_kernel.hpp"

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
};

template <class M, int NR, bool Box, bool FieldParams>
inline void explicit_row(const ExplicitRow& a) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams;
  const double* __restrict__ src[NS * NR];
  double* __restrict__ dst[NS];
  double w[NR][3], D[NS], floor[NS], pc[NP > 0 ? NP : 1];
  const double* __restrict__ prow[NP > 0 ? NP : 1];
  for (int q = 0; q < NS * NR; ++q)
    src[q] = a.src[q];
  for (int r = 0; r < NR; ++r)
    for (int c = 0; c < 3; ++c)
      w[r][c] = a.w[3 * r + c];
  for (int s = 0; s < NS; ++s) {
    dst[s] = a.dst[s];
    D[s] = a.D[s];
    floor[s] = a.floor[s];
  }
  for (int q = 0; q < NP; ++q) {
    if constexpr (FieldParams)
      prow[q] = a.prow[q];
    else
      pc[q] = a.pconst[q];
  }
  const double dt = a.dt;
  const int n = a.n;
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) {
    double u[NS], r[NS], p[NP > 0 ? NP : 1];
    for (int q = 0; q < NP; ++q) {
      if constexpr (FieldParams)
        p[q] = prow[q][i];
      else
        p[q] = pc[q];
    }
    for (int s = 0; s < NS; ++s)
      u[s] = src[s * NR][i];
    M::rates(u, p, r);
    for (int s = 0; s < NS; ++s) {
      const double* __restrict__ c = src[s * NR];
      double lap = w[0][0] * c[i - 1] + w[0][1] * u[s] + w[0][2] * c[i + 1];
      for (int q = 1; q < NR; ++q) {
        const double* __restrict__ row = src[s * NR + q];
        if constexpr (Box)
          lap += w[q][0] * row[i - 1] + w[q][1] * row[i] + w[q][2] * row[i + 1];
        else
          lap += w[q][1] * row[i];
      }
      const double v = u[s] + dt * (D[s] * lap + r[s]);
      dst[s][i] = clamp_to_floor(v, floor[s]);
    }
  }
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
      const double v = u[s] + dt * (div[s][i] + r[s]);
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
      const double v = u[i] + dt * (div[i] + rs[i]);
      dst[i] = clamp_to_floor(v, floor);
    }
  }
}

template <class M, bool FieldParams> inline void explicit_row_pre(const ExplicitRow& a) {
  explicit_row_pre_of<M::nspecies, M::nparams, FieldParams>(M{}, M::nparams, a);
}

} // namespace morphogen
