// Lockstep Newton for the implicit reaction substep of a compiled model with 2 or 3 species
// (pure kernel: no PETSc, MPI, allocation, exceptions or virtuals).
//
// The same per-cell problem and the same iteration as reaction_cell_of (reaction_kernel.hpp):
//   BackwardEuler  F(v) = v - u - dt (R(v) + S1)                     = 0
//   Trapezoidal    F(v) = v - u - dt/2 (R(u) + S0 + R(v) + S1)       = 0
// started from the better of u and the explicit Euler predictor, full Newton steps
//   (I - c dt dR/du(v)) dv = -F(v),  v <- v + dv,
// converged when ||dv||_inf <= tol (1 + max(||u||_inf, ||v||_inf)), but solved for W cells of
// a row at once: every loop runs over the W lanes with branch-free selects (GCC vectorises it),
// the linear solve is Cramer's rule on the analytic Jacobian (2x2, 3x3), and a converged lane
// is frozen (it keeps the iterate at which it converged, as the per-cell solver returns it).
// A lane that would need anything else - a damped step (the step is large and the full step
// fails the per-cell solver's Armijo test), a (near-)singular Jacobian (|det| <= 64 eps
// ||A||_inf^N), a non-finite value, or more than maxit iterations - is redone by
// reaction_cell_of from its inputs, so damping and every failure report are exactly the
// per-cell solver's. Results agree with the per-cell solver to rounding (Cramer vs. pivoted
// LU: a few ulps of the update, far below tol; tests/integrators/test_reaction_lockstep.cpp).
//
// reaction_row_lockstep has reaction_row's contract (reaction_kernel.hpp: clamped outputs,
// -1 or the first failed cell, *worst, out may alias u) and falls back to it for the explicit
// schemes and for models with other species counts.
#pragma once

#include "integrators/reaction_kernel.hpp"

#include <cfloat>

namespace morphogen {

namespace detail {

inline bool finite_d(double x) {
  return std::fabs(x) <= DBL_MAX;
} // false for NaN and inf

// x = A^-1 b for N = 2, 3 (row-major A) by Cramer's rule; false when |det| <= 64 eps ||A||^N.
template <int N> inline bool cramer_solve(const double* A, const double* b, double* x) {
  static_assert(N == 2 || N == 3, "cramer_solve: 2 or 3 unknowns");
  double norm = 0.0;
  for (int r = 0; r < N; ++r) {
    double row = 0.0;
#pragma GCC unroll 16
    for (int c = 0; c < N; ++c)
      row += std::fabs(A[r * N + c]);
    norm = row > norm ? row : norm;
  }
  if constexpr (N == 2) {
    const double det = A[0] * A[3] - A[1] * A[2];
    const double inv = 1.0 / det;
    x[0] = (b[0] * A[3] - A[1] * b[1]) * inv;
    x[1] = (A[0] * b[1] - A[2] * b[0]) * inv;
    return std::fabs(det) > 64.0 * DBL_EPSILON * norm * norm;
  } else {
    const double c00 = A[4] * A[8] - A[5] * A[7], c01 = A[5] * A[6] - A[3] * A[8],
                 c02 = A[3] * A[7] - A[4] * A[6];
    const double det = A[0] * c00 + A[1] * c01 + A[2] * c02;
    const double inv = 1.0 / det;
    x[0] = (c00 * b[0] + (A[2] * A[7] - A[1] * A[8]) * b[1] + (A[1] * A[5] - A[2] * A[4]) * b[2]) *
           inv;
    x[1] = (c01 * b[0] + (A[0] * A[8] - A[2] * A[6]) * b[1] + (A[2] * A[3] - A[0] * A[5]) * b[2]) *
           inv;
    x[2] = (c02 * b[0] + (A[1] * A[6] - A[0] * A[7]) * b[1] + (A[0] * A[4] - A[1] * A[3]) * b[2]) *
           inv;
    return std::fabs(det) > 64.0 * DBL_EPSILON * norm * norm * norm;
  }
}

// The W lanes of one chunk: inputs, iterate and per-lane state (0/1 flags as doubles so that
// every select vectorises).
template <int NS, int NP, int W> struct LockstepLanes {
  double u[NS][W], s0[NS][W], s1[NS][W], p[NP][W];
  double base[NS][W], v[NS][W], F[NS][W], unorm[W], res[W], its[W], done[W], bad[W];
};

// Start: base, the better of u and the Euler predictor, its residual; lanes with a non-finite
// start are bad, lanes with a zero residual are done.
template <class M, int NS, int NP, int W>
inline void lockstep_start(LockstepLanes<NS, NP, W>& L, bool trap, double cdt) {
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    double uc[NS], pc[NP], ru[NS], pred[NS], rp[NS];
#pragma GCC unroll 16
    for (int q = 0; q < NP; ++q)
      pc[q] = L.p[q][l];
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s)
      uc[s] = L.u[s][l];
    M::rates(uc, pc, ru);
    double un = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      L.base[s][l] = trap ? uc[s] + cdt * (ru[s] + L.s0[s][l]) : uc[s];
      pred[s] = L.base[s][l] + cdt * (ru[s] + L.s1[s][l]);
      const double a = std::fabs(uc[s]);
      un = a > un ? a : un;
    }
    M::rates(pred, pc, rp);
    double resp = 0.0, resu = 0.0, fin = 0.0, finu = 0.0; // sums: NaN/inf show there
    double Fp[NS];
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      Fp[s] = pred[s] - L.base[s][l] - cdt * (rp[s] + L.s1[s][l]);
      const double ap = std::fabs(Fp[s]), au = std::fabs(uc[s] - pred[s]);
      resp = ap > resp ? ap : resp;
      resu = au > resu ? au : resu;
      fin += Fp[s];
      finu += uc[s] + pred[s];
    }
    const bool usep = finite_d(fin) & (resp < resu);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      L.v[s][l] = usep ? pred[s] : uc[s];
      L.F[s][l] = usep ? Fp[s] : uc[s] - pred[s];
    }
    const double res = usep ? resp : resu;
    L.res[l] = res;
    L.unorm[l] = un;
    L.its[l] = 0.0;
    L.bad[l] = finite_d(finu) ? 0.0 : 1.0;
    L.done[l] = (L.bad[l] == 0.0) & (res == 0.0) ? 1.0 : 0.0;
  }
}

// One full Newton step on every active lane; returns the number of lanes still active.
template <class M, int NS, int NP, int W>
inline int lockstep_newton(LockstepLanes<NS, NP, W>& L, double cdt, double tol, double big,
                           int it) {
  int active = 0;
#pragma GCC ivdep
  for (int l = 0; l < W; ++l) {
    double vc[NS], pc[NP], J[NS * NS], rhs[NS], dv[NS], vt[NS], r[NS], Ft[NS];
#pragma GCC unroll 16
    for (int q = 0; q < NP; ++q)
      pc[q] = L.p[q][l];
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s)
      vc[s] = L.v[s][l];
    M::jacobian(vc, pc, J);
#pragma GCC unroll 16
    for (int q = 0; q < NS * NS; ++q)
      J[q] *= -cdt;
    double f2 = 0.0, step = 0.0, vcn = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      J[s * NS + s] += 1.0;
      rhs[s] = -L.F[s][l];
      f2 += L.F[s][l] * L.F[s][l];
    }
    const bool regular = cramer_solve<NS>(J, rhs, dv);
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      vt[s] = vc[s] + dv[s];
      const double a = std::fabs(dv[s]), c = std::fabs(vc[s]);
      step = a > step ? a : step;
      vcn = c > vcn ? c : vcn;
    }
    M::rates(vt, pc, r);
    double rest = 0.0, ft2 = 0.0, vtn = 0.0, fin = 0.0;
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      Ft[s] = vt[s] - L.base[s][l] - cdt * (r[s] + L.s1[s][l]);
      const double a = std::fabs(Ft[s]), b = std::fabs(vt[s]);
      rest = a > rest ? a : rest;
      ft2 += Ft[s] * Ft[s];
      vtn = b > vtn ? b : vtn;
      fin += Ft[s];
    }
    const double un = L.unorm[l];
    // Bitwise & and | (no short-circuit branches), so that GCC if-converts and vectorises.
    const bool far = step > big * (1.0 + (un > vcn ? un : vcn));
    const bool armijo = ft2 <= (1.0 - 2e-4) * f2;
    const bool act = (L.done[l] == 0.0) & (L.bad[l] == 0.0);
    const bool fail = !regular | !finite_d(fin) | (far & !armijo);
    const bool take = act & !fail;
    // Every lane stores (selects of values read above, no conditional stores).
    const double res0 = L.res[l], its0 = L.its[l], bad0 = L.bad[l], done0 = L.done[l];
#pragma GCC unroll 16
    for (int s = 0; s < NS; ++s) {
      const double F0 = -rhs[s];
      L.v[s][l] = take ? vt[s] : vc[s];
      L.F[s][l] = take ? Ft[s] : F0;
    }
    L.res[l] = take ? rest : res0;
    L.its[l] = take ? static_cast<double>(it) : its0;
    L.bad[l] = act & fail ? 1.0 : bad0;
    const bool conv = step <= tol * (1.0 + (un > vtn ? un : vtn));
    L.done[l] = take & conv ? 1.0 : done0;
    active += take & !conv ? 1 : 0;
  }
  return active;
}

} // namespace detail

template <class M, bool FieldParams>
inline int reaction_row_lockstep(ReactionScheme scheme, int n, const double* const* u,
                                 const double* const* prow, const double* pconst,
                                 const double* const* S0, const double* const* S1, double dt,
                                 double tol, int maxit, const double* floor, double* const* out,
                                 CellSolve* worst) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams > 0 ? M::nparams : 1;
  constexpr int W = 8;
  const bool implicit =
      scheme == ReactionScheme::BackwardEuler || scheme == ReactionScheme::Trapezoidal;
  if constexpr (NS != 2 && NS != 3)
    return reaction_row<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor,
                                        out, worst);
  else if (!implicit || maxit < 1)
    return reaction_row<M, FieldParams>(scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor,
                                        out, worst);
  else {
    const bool trap = scheme == ReactionScheme::Trapezoidal;
    const double cdt = trap ? 0.5 * dt : dt;
    const double big = std::sqrt(tol);
    CellSolve acc{0, 0.0, true};
    detail::LockstepLanes<NS, NP, W> L;
    for (int i0 = 0; i0 < n; i0 += W) {
      const int w = n - i0 < W ? n - i0 : W;
      for (int l = 0; l < W; ++l) { // lanes past the row repeat its last cell
        const int i = i0 + (l < w ? l : w - 1);
#pragma GCC unroll 16
        for (int s = 0; s < NS; ++s) {
          L.u[s][l] = u[s][i];
          L.s0[s][l] = S0 ? S0[s][i] : 0.0;
          L.s1[s][l] = S1 ? S1[s][i] : 0.0;
        }
#pragma GCC unroll 16
        for (int q = 0; q < M::nparams; ++q)
          L.p[q][l] = FieldParams ? prow[q][i] : pconst[q];
      }
      detail::lockstep_start<M>(L, trap, cdt);
      for (int it = 1; it <= maxit; ++it)
        if (detail::lockstep_newton<M>(L, cdt, tol, big, it) == 0) break;
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
    if (worst) *worst = acc;
    return -1;
  }
}

} // namespace morphogen
