// Explicit reaction substeps of a compiled model over a row, vectorised (pure kernel: no
// PETSc, MPI, allocation, exceptions or virtuals):
//   Euler  v = u + dt (R(u) + S0)
//   Heun   k1 = R(u) + S0,  w = u + dt k1,  v = u + dt/2 (k1 + R(w) + S1)
//   Rk4    the classical Runge-Kutta step, sources S0, (S0 + S1)/2, (S0 + S1)/2, S1
// The same arithmetic as reaction_cell_of's explicit schemes (detail::explicit_cell), computed
// for W = 16 cells at once in one branch-free loop over the lanes (reaction_lanes.hpp), which GCC
// vectorises (the whole row function with 512-bit vectors where the target has them,
// MG_LANES_WIDE: the lane loop inlines into it and takes its vector width); the per-cell path calls
// the whole Newton-capable cell solver per cell (about 20 ns against 1-5 ns here). With scalar
// parameters and no sources (the common case) full chunks read the row and write the result
// directly, without the lane buffers (Brusselator rk4 1.9-2.0 against 2.6-2.8 ns per cell,
// Heun 1.2-1.3 against 1.9-2.0: morphogen-bench's split_reaction_kernel). Values agree
// with it to an ulp (the compiler may contract a multiply-add differently in vector code) and do
// not depend on a cell's place in the row.
//
// reaction_row_explicit has reaction_row's contract: outputs clamped to floor, out may alias u,
// returns -1, or the first cell whose new value is not finite (the cells before it written, it
// and the rest not), *worst = {0 iterations, residual 0, converged}.
#pragma once

#include "integrators/reaction_kernel.hpp"
#include "integrators/reaction_lanes.hpp"

namespace morphogen {

namespace detail {

// v = the scheme's new value on every lane; fin[l] = 1 where lane l's values are finite, else 0
// (per lane, not a running sum: a floating-point reduction would keep the loop scalar).
template <class M, ReactionScheme S, int NP, int W>
MG_LANES_WIDE inline void explicit_lanes(LockstepLanes<M::nspecies, NP, W>& L, double dt,
                                         double* fin) {
  constexpr int NS = M::nspecies;
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    double uc[NS], pc[NP], ru[NS], a[NS], b[NS], v[NS];
    lane_state(L.u, l, uc);
    lane_params<true>(L.p, nullptr, l, pc);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      a[s] = L.s0[s][l];
      b[s] = L.s1[s][l];
    }
    M::rates(uc, pc, ru);
    explicit_cell<S, NS>(M{}, uc, pc, ru, a, b, dt, v);
    double sum = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      L.v[s][l] = v[s];
      sum += v[s];
    }
    fin[l] = finite_mask(sum);
  }
}

template <class M, bool FieldParams, ReactionScheme S>
MG_LANES_WIDE inline int explicit_row_lanes(int n, const double* const* u,
                                            const double* const* prow, const double* pconst,
                                            const double* const* S0, const double* const* S1,
                                            double dt, const double* floor, double* const* out) {
  constexpr int NS = M::nspecies, NP = M::nparams > 0 ? M::nparams : 1, W = 16;
  LockstepLanes<NS, NP, W> L;
  for (int i0 = 0; i0 < n; i0 += W) {
    const int w = n - i0 < W ? n - i0 : W;
    lockstep_load<NS, NP, W, FieldParams>(L, i0, w, M::nparams, u, prow, pconst, S0, S1);
    double fin[W];
    explicit_lanes<M, S, NP, W>(L, dt, fin);
    int stop = 0; // lanes to store: all, or those before the first non-finite one
    while (stop < w && fin[stop] != 0.0)
      ++stop;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      const double f = floor[s];
      double* o = out[s] + i0;
      for (int l = 0; l < stop; ++l)
        o[l] = clamp_to_floor(L.v[s][l], f);
    }
    if (stop < w) return i0 + stop;
  }
  return -1;
}

// explicit_row_lanes from cell i0 of the row on; its result in the row's numbering.
template <class M, bool FieldParams, ReactionScheme S>
__attribute__((noinline, cold)) int
explicit_row_from(int i0, int n, const double* const* u, const double* const* prow,
                  const double* pconst, const double* const* S0, const double* const* S1, double dt,
                  const double* floor, double* const* out) {
  constexpr int NS = M::nspecies, NP = M::nparams > 0 ? M::nparams : 1;
  const double *ui[NS], *pi[NP], *ai[NS], *bi[NS];
  double* oi[NS];
  for (int s = 0; s < NS; ++s) {
    ui[s] = u[s] + i0;
    oi[s] = out[s] + i0;
    ai[s] = S0 ? S0[s] + i0 : nullptr;
    bi[s] = S1 ? S1[s] + i0 : nullptr;
  }
  for (int q = 0; q < M::nparams; ++q)
    pi[q] = FieldParams ? prow[q] + i0 : nullptr;
  const int bad =
      explicit_row_lanes<M, FieldParams, S>(n - i0, ui, FieldParams ? pi : prow, pconst,
                                            S0 ? ai : nullptr, S1 ? bi : nullptr, dt, floor, oi);
  return bad < 0 ? -1 : i0 + bad;
}

// The common case (scalar parameters, no sources) without the lane buffers: each full chunk
// computed straight from the row and stored when all its cells are finite (the same arithmetic,
// the sources' zeros included); a chunk with a non-finite cell, and the row's last partial chunk,
// go through explicit_row_lanes.
template <class M, bool FieldParams, ReactionScheme S>
MG_LANES_WIDE inline int explicit_row(int n, const double* const* u, const double* const* prow,
                                      const double* pconst, const double* const* S0,
                                      const double* const* S1, double dt, const double* floor,
                                      double* const* out) {
  constexpr int NS = M::nspecies, NP = M::nparams > 0 ? M::nparams : 1, W = 16;
  if (FieldParams || S0 || S1)
    return explicit_row_lanes<M, FieldParams, S>(n, u, prow, pconst, S0, S1, dt, floor, out);
  double pc[NP] = {};
  for (int q = 0; q < M::nparams; ++q)
    pc[q] = pconst[q];
  const int full = n / W * W;
  for (int i0 = 0; i0 < full; i0 += W) {
    double v[NS][W], fin[W];
#pragma GCC ivdep
    for (int l = 0; l < W; ++l) {
      double uc[NS], ru[NS], zero[NS], vc[NS];
#pragma GCC unroll 16
      for (int s = 0; s < NS; ++s) {
        uc[s] = u[s][i0 + l];
        zero[s] = 0.0;
      }
      M::rates(uc, pc, ru);
      explicit_cell<S, NS>(M{}, uc, pc, ru, zero, zero, dt, vc);
      double sum = 0.0;
#pragma GCC unroll 16
      for (int s = 0; s < NS; ++s) {
        v[s][l] = vc[s];
        sum += vc[s];
      }
      fin[l] = finite_mask(sum);
    }
    double all = 1.0;
    for (int l = 0; l < W; ++l)
      all = all < fin[l] ? all : fin[l];
    if (all == 0.0)
      return explicit_row_from<M, FieldParams, S>(i0, n, u, prow, pconst, S0, S1, dt, floor, out);
    store_clamped<NS, W>(v, i0, floor, out);
  }
  return full == n ? -1
                   : explicit_row_from<M, FieldParams, S>(full, n, u, prow, pconst, S0, S1, dt,
                                                          floor, out);
}

} // namespace detail

// Euler, Heun or Rk4 (see the header comment); an implicit scheme is taken as Rk4.
template <class M, bool FieldParams>
inline int reaction_row_explicit(ReactionScheme scheme, int n, const double* const* u,
                                 const double* const* prow, const double* pconst,
                                 const double* const* S0, const double* const* S1, double dt,
                                 const double* floor, double* const* out, CellSolve* worst) {
  using RS = ReactionScheme;
  const int bad =
      scheme == RS::Euler  ? detail::explicit_row<M, FieldParams, RS::Euler>(n, u, prow, pconst, S0,
                                                                            S1, dt, floor, out)
      : scheme == RS::Heun ? detail::explicit_row<M, FieldParams, RS::Heun>(n, u, prow, pconst, S0,
                                                                            S1, dt, floor, out)
                           : detail::explicit_row<M, FieldParams, RS::Rk4>(n, u, prow, pconst, S0,
                                                                           S1, dt, floor, out);
  if (worst) *worst = CellSolve{0, 0.0, bad < 0};
  return bad;
}

} // namespace morphogen
