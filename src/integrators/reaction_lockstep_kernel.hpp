// Lockstep Newton for the implicit reaction substep of a compiled model with 2 or 3 species
// (pure kernel: no PETSc, MPI, allocation, exceptions or virtuals).
//
// The same per-cell problem and the same iteration as reaction_cell_of (reaction_kernel.hpp):
//   BackwardEuler  F(v) = v - u - dt (R(v) + S1)                     = 0
//   Trapezoidal    F(v) = v - u - dt/2 (R(u) + S0 + R(v) + S1)       = 0
// started from the better of u and the explicit Euler predictor, full Newton steps
//   (I - c dt dR/du(v)) dv = -F(v),  v <- v + dv,
// converged by the first two of reaction_kernel.hpp's tests (||dv||_inf or twice the next update
// ||A^-1 F(v)||_inf, by the same Cramer inverse, <= tol (1 + max(||u||_inf, ||v||_inf)); the
// third, the contraction estimate, stops only what has reached the round-off floor above a tol
// near machine epsilon, whose lanes run to maxit here and go to the per-cell solver with
// everything else below), but solved for W = 64
// cells of a row at once, held as structure-of-arrays (one array per species/state over the lanes):
// the start and each Newton step is one loop over the lanes with no branches - 0/1 masks held as
// doubles, selects, no early exit per lane - so GCC vectorises it (-fopt-info-vec reports "loop
// vectorized" for lockstep_start and lockstep_newton; 512-bit vectors where the target has
// AVX-512), the linear solve is Cramer's rule on the analytic Jacobian (2x2, 3x3), and a converged
// lane is frozen by the masks (it keeps the iterate at which it converged, as the per-cell solver
// returns it). Steps repeat until no lane of the chunk is active. A full chunk in which every lane
// converged (the usual case) is loaded and stored by plain vector copies. A lane that would need
// anything else - a damped step (the step is large and the full step fails the per-cell solver's
// Armijo test), a (near-)singular Jacobian (|det| <= 64 eps
// ||A||_inf^N), a non-finite value, or more than maxit iterations - is redone by
// reaction_cell_of from its inputs, so damping and every failure report are exactly the
// per-cell solver's. Results agree with the per-cell solver to rounding (Cramer vs. pivoted
// LU: a few ulps of the update, far below tol; tests/integrators/test_reaction_lockstep.cpp).
// A row without sources runs an instantiation that adds no zero sources, and scalar parameters
// are read as the scalars themselves, not per lane: the same arithmetic, so the same values.
//
// reaction_row_lockstep has reaction_row's contract (reaction_kernel.hpp: clamped outputs,
// -1 or the first failed cell, *worst, out may alias u); the explicit schemes go to the
// vectorised reaction_row_explicit (reaction_explicit_kernel.hpp), models with other species
// counts to reaction_row.
#pragma once

#include "integrators/reaction_explicit_kernel.hpp"
#include "integrators/reaction_kernel.hpp"
#include "integrators/reaction_lanes.hpp"

#include <cfloat>

namespace morphogen {

namespace detail {

// x = det(A) A^-1 b for N = 2, 3 (row-major A): Cramer's numerators.
template <int N> inline void cramer_numerators(const double* A, const double* b, double* x) {
  if constexpr (N == 2) {
    x[0] = b[0] * A[3] - A[1] * b[1];
    x[1] = A[0] * b[1] - A[2] * b[0];
  } else {
    const double c00 = A[4] * A[8] - A[5] * A[7], c01 = A[5] * A[6] - A[3] * A[8],
                 c02 = A[3] * A[7] - A[4] * A[6];
    x[0] = c00 * b[0] + (A[2] * A[7] - A[1] * A[8]) * b[1] + (A[1] * A[5] - A[2] * A[4]) * b[2];
    x[1] = c01 * b[0] + (A[0] * A[8] - A[2] * A[6]) * b[1] + (A[2] * A[3] - A[0] * A[5]) * b[2];
    x[2] = c02 * b[0] + (A[1] * A[6] - A[0] * A[7]) * b[1] + (A[0] * A[4] - A[1] * A[3]) * b[2];
  }
}

// max_k |x[k]| for the lanes (branch-free, from |x[0]| on). Unlike the per-cell solver's
// detail::max_abs it does not carry a NaN through (that costs a compare per entry in this loop,
// measured about 10 % of the row): a lane with a NaN here fails its finiteness test anyway.
template <int N> inline double lane_max_abs(const double* x) {
  double m = 0.0;
#pragma GCC unroll 16
  for (int k = 0; k < N; ++k) {
    const double a = std::fabs(x[k]);
    m = k == 0 || a > m ? a : m;
  }
  return m;
}

// x = A^-1 b for N = 2, 3 (row-major A) by Cramer's rule, *inv_det = 1 / det A; returns 1.0, or
// 0.0 when |det| <= 64 eps ||A||_inf^N (numerically singular; x is then unspecified).
// Branch-free.
template <int N>
inline double cramer_lane(const double* A, const double* b, double* x, double* inv_det) {
  static_assert(N == 2 || N == 3, "cramer_solve: 2 or 3 unknowns");
  double norm = 0.0;
#pragma GCC unroll 16
  for (int r = 0; r < N; ++r) {
    double row = 0.0;
#pragma GCC unroll 16
    for (int c = 0; c < N; ++c) {
      const double a = std::fabs(A[r * N + c]);
      row = c == 0 ? a : row + a;
    }
    norm = r == 0 || row > norm ? row : norm;
  }
  double det;
  if constexpr (N == 2)
    det = A[0] * A[3] - A[1] * A[2];
  else
    det = A[0] * (A[4] * A[8] - A[5] * A[7]) + A[1] * (A[5] * A[6] - A[3] * A[8]) +
          A[2] * (A[3] * A[7] - A[4] * A[6]);
  const double inv = 1.0 / det;
  *inv_det = inv;
  cramer_numerators<N>(A, b, x);
#pragma GCC unroll 16
  for (int k = 0; k < N; ++k)
    x[k] *= inv;
  double bound = 64.0 * DBL_EPSILON * norm;
  for (int k = 1; k < N; ++k)
    bound *= norm;
  return std::fabs(det) > bound ? 1.0 : 0.0;
}

template <int N> inline bool cramer_solve(const double* A, const double* b, double* x) {
  double inv;
  return cramer_lane<N>(A, b, x, &inv) != 0.0;
}

// Start: base, the better of u and the Euler predictor, its residual; lanes with a non-finite
// start are bad, lanes with a zero residual are done.
template <class M, bool FP, bool Src, int NS, int NP, int W>
MG_LANES_WIDE inline void lockstep_start(LockstepLanes<NS, NP, W>& L, const double* pconst,
                                         double trap, double cdt) {
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    double uc[NS], pc[NP], ru[NS], pred[NS], rp[NS], Fp[NS];
    lane_state(L.u, l, uc);
    lane_params<FP || M::nparams == 0>(L.p, pconst, l, pc); // no pconst[0] without parameters
    M::rates(uc, pc, ru);
    double du[NS], fin = 0.0, finu = 0.0; // sums: NaN/inf show there
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      const double b = uc[s] + trap * cdt * plus_source<Src>(ru[s], L.s0[s][l]);
      L.base[s][l] = b;
      pred[s] = b + cdt * plus_source<Src>(ru[s], L.s1[s][l]);
    }
    M::rates(pred, pc, rp);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      Fp[s] = pred[s] - L.base[s][l] - cdt * plus_source<Src>(rp[s], L.s1[s][l]);
      du[s] = uc[s] - pred[s];
      fin += Fp[s];
      finu += uc[s] + pred[s];
    }
    const double un = lane_max_abs<NS>(uc), resp = lane_max_abs<NS>(Fp),
                 resu = lane_max_abs<NS>(du);
    const double usep = finite_mask(fin) * (resp < resu ? 1.0 : 0.0);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      L.v[s][l] = usep != 0.0 ? pred[s] : uc[s];
      L.F[s][l] = usep != 0.0 ? Fp[s] : du[s];
    }
    const double res = usep != 0.0 ? resp : resu;
    const double bad = 1.0 - finite_mask(finu);
    L.res[l] = res;
    L.unorm[l] = un;
    L.its[l] = 0.0;
    L.done[l] = bad == 0.0 && res == 0.0 ? 1.0 : 0.0;
    L.act[l] = (1.0 - bad) * (res != 0.0 ? 1.0 : 0.0);
  }
}

// One full Newton step on every active lane (branch-free: every lane computes, selects keep
// the finished ones).
template <class M, bool FP, bool Src, int NS, int NP, int W>
MG_LANES_WIDE MG_LANES_INLINE void lockstep_newton(LockstepLanes<NS, NP, W>& L,
                                                   const double* pconst, double cdt, double tol,
                                                   double big, double it) {
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    double vc[NS], pc[NP], J[NS * NS], rhs[NS], dv[NS], vt[NS], r[NS], Ft[NS];
    lane_state(L.v, l, vc);
    lane_params<FP || M::nparams == 0>(L.p, pconst, l, pc); // no pconst[0] without parameters
    M::jacobian(vc, pc, J);
#pragma GCC unroll 16
    for (int q = 0; q < NS * NS; ++q)
      J[q] *= -cdt;
    double f2 = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      J[s * NS + s] += 1.0;
      rhs[s] = -L.F[s][l];
      f2 += L.F[s][l] * L.F[s][l];
    }
    double inv;
    const double regular = cramer_lane<NS>(J, rhs, dv, &inv);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s)
      vt[s] = vc[s] + dv[s];
    const double step = lane_max_abs<NS>(dv), vcn = lane_max_abs<NS>(vc),
                 vtn = lane_max_abs<NS>(vt);
    M::rates(vt, pc, r);
    double ft2 = 0.0, fin = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      Ft[s] = vt[s] - L.base[s][l] - cdt * plus_source<Src>(r[s], L.s1[s][l]);
      ft2 += Ft[s] * Ft[s];
      fin += Ft[s];
    }
    const double rest = lane_max_abs<NS>(Ft);
    const double un = L.unorm[l];
    const double far = step > big * (1.0 + (un > vcn ? un : vcn)) ? 1.0 : 0.0;
    const double armijo = ft2 <= (1.0 - 2e-4) * f2 ? 1.0 : 0.0;
    const double act = L.act[l];
    const double ok = regular * finite_mask(fin) * (1.0 - far * (1.0 - armijo));
    const double take = act * ok;
    double ahead[NS]; // A^-1 F(vt) = ahead / det: about the error left in vt
    cramer_numerators<NS>(J, Ft, ahead);
    const double num = lane_max_abs<NS>(ahead);
    const double bound = tol * (1.0 + (un > vtn ? un : vtn));
    const double conv = newton_update_converged_mask(step, num * std::fabs(inv), bound);
    const double res0 = L.res[l], its0 = L.its[l];
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      const double F0 = -rhs[s];
      L.v[s][l] = take != 0.0 ? vt[s] : vc[s];
      L.F[s][l] = take != 0.0 ? Ft[s] : F0;
    }
    L.res[l] = take != 0.0 ? rest : res0;
    L.its[l] = take != 0.0 ? it : its0;
    L.done[l] += take * conv;
    L.act[l] = take * (1.0 - conv);
  }
}

// Lanes still iterating (neither converged nor handed to the per-cell solver). (Integer
// reductions: they vectorise, where a floating-point sum or product would be a serial chain.)
template <int NS, int NP, int W>
inline bool lockstep_any_active(const LockstepLanes<NS, NP, W>& L) {
  int busy = 0;
  for (int l = 0; l < W; ++l)
    busy |= static_cast<int>(L.act[l] != 0.0);
  return busy != 0;
}

// Every lane converged in the lockstep (no lane needs the per-cell solver).
template <int NS, int NP, int W> inline bool lockstep_all_done(const LockstepLanes<NS, NP, W>& L) {
  int all = 1;
  for (int l = 0; l < W; ++l)
    all &= static_cast<int>(L.done[l] != 0.0);
  return all != 0;
}

// A full, converged chunk: clamped outputs, per-lane running maxima of iterations and residual.
template <int NS, int NP, int W>
inline void lockstep_store(const LockstepLanes<NS, NP, W>& L, int i0, const double* floor,
                           double* const* out, double* its_max, double* res_max) {
  store_clamped<NS, W>(L.v, i0, floor, out);
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    its_max[l] = L.its[l] > its_max[l] ? L.its[l] : its_max[l];
    res_max[l] = L.res[l] > res_max[l] ? L.res[l] : res_max[l];
  }
}

// The implicit row (2-3 species, maxit >= 1): chunks of kLockstepLanes cells. 64 lanes keep
// enough independent vectors in flight that a Newton step's dependency chain (Jacobian, the
// division of Cramer's rule, rates, masks) does not set the pace; a lane's arithmetic does
// not depend on the chunk width.
constexpr int kLockstepLanes = 64;

template <class M, bool FieldParams, bool Src>
MG_LANES_WIDE inline int
lockstep_implicit_row_of(ReactionScheme scheme, int n, const double* const* u,
                         const double* const* prow, const double* pconst, const double* const* S0,
                         const double* const* S1, double dt, double tol, int maxit,
                         const double* floor, double* const* out, CellSolve* worst) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams > 0 ? M::nparams : 1;
  constexpr int W = kLockstepLanes;
  const bool trap = scheme == ReactionScheme::Trapezoidal;
  const double cdt = trap ? 0.5 * dt : dt;
  const double big = std::sqrt(tol);
  CellSolve acc{0, 0.0, true};
  double its_max[W] = {}, res_max[W] = {};
  LockstepLanes<NS, NP, W> L;
  for (int i0 = 0; i0 < n; i0 += W) {
    const int w = n - i0 < W ? n - i0 : W;
    lockstep_load<NS, NP, W, FieldParams>(L, i0, w, M::nparams, u, prow, pconst, S0, S1);
    lockstep_start<M, FieldParams, Src>(L, pconst, trap ? 1.0 : 0.0, cdt);
    for (int it = 1; it <= maxit && lockstep_any_active(L); ++it)
      lockstep_newton<M, FieldParams, Src>(L, pconst, cdt, tol, big, static_cast<double>(it));
    if (w == W && lockstep_all_done(L)) {
      lockstep_store(L, i0, floor, out, its_max, res_max);
      continue;
    }
    for (int l = 0; l < w; ++l) {
      double v[NS];
      CellSolve cs{static_cast<int>(L.its[l]), L.res[l], true};
#pragma GCC unroll 16
      for (int s = 0; s < NS; ++s)
        v[s] = L.v[s][l];
      if (L.done[l] == 0.0) { // the per-cell solver: damping, or its failure report
        double uc[NS], a[NS], b[NS], pc[NP];
#pragma GCC unroll 16
        for (int s = 0; s < NS; ++s) {
          uc[s] = L.u[s][l];
          a[s] = L.s0[s][l];
          b[s] = L.s1[s][l];
        }
#pragma GCC unroll 16
        for (int q = 0; q < NP; ++q)
          pc[q] = L.p[q][l];
        cs = reaction_cell_of<NS>(M{}, scheme, uc, pc, a, b, dt, tol, maxit, v);
        if (!cs.converged) {
          if (worst) *worst = cs;
          return i0 + l;
        }
      }
      if (cs.iterations > acc.iterations) acc.iterations = cs.iterations;
      if (cs.residual > acc.residual) acc.residual = cs.residual;
#pragma GCC unroll 16
      for (int s = 0; s < NS; ++s)
        out[s][i0 + l] = clamp_to_floor(v[s], floor[s]);
    }
  }
  for (int l = 0; l < W; ++l) {
    if (its_max[l] > acc.iterations) acc.iterations = static_cast<int>(its_max[l]);
    if (res_max[l] > acc.residual) acc.residual = res_max[l];
  }
  if (worst) *worst = acc;
  return -1;
}

// The row with or without sources (S0, S1 null: none; the source-free lanes skip adding zeros).
template <class M, bool FieldParams>
MG_LANES_WIDE inline int
lockstep_implicit_row(ReactionScheme scheme, int n, const double* const* u,
                      const double* const* prow, const double* pconst, const double* const* S0,
                      const double* const* S1, double dt, double tol, int maxit,
                      const double* floor, double* const* out, CellSolve* worst) {
  if (S0 || S1)
    return lockstep_implicit_row_of<M, FieldParams, true>(scheme, n, u, prow, pconst, S0, S1, dt,
                                                          tol, maxit, floor, out, worst);
  return lockstep_implicit_row_of<M, FieldParams, false>(scheme, n, u, prow, pconst, S0, S1, dt,
                                                         tol, maxit, floor, out, worst);
}

} // namespace detail

template <class M, bool FieldParams>
inline int reaction_row_lockstep(ReactionScheme scheme, int n, const double* const* u,
                                 const double* const* prow, const double* pconst,
                                 const double* const* S0, const double* const* S1, double dt,
                                 double tol, int maxit, const double* floor, double* const* out,
                                 CellSolve* worst) {
  constexpr int NS = M::nspecies;
  const bool implicit =
      scheme == ReactionScheme::BackwardEuler || scheme == ReactionScheme::Trapezoidal;
  if (scheme == ReactionScheme::Euler || scheme == ReactionScheme::Heun ||
      scheme == ReactionScheme::Rk4)
    return reaction_row_explicit<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt, floor, out,
                                                 worst);
  if constexpr (NS != 2 && NS != 3)
    return reaction_row<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor,
                                        out, worst);
  else if (!implicit || maxit < 1)
    return reaction_row<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor,
                                        out, worst);
  else
    return detail::lockstep_implicit_row<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt,
                                                         tol, maxit, floor, out, worst);
}

} // namespace morphogen
