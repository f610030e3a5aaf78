// Per-cell reaction update (pure kernels: no PETSc, MPI, allocation, exceptions or virtuals).
//
// For one cell, the reaction ODE  du/dt = R(u; p) + S(t)  is advanced by one step dt from u to
// v. S is a source term (e.g. the explicitly treated diffusion/advection of a splitting scheme);
// S0 = S at the start of the step, S1 = S at the end (either may be nullptr for zero):
//   Euler          v = u + dt (R(u) + S0)                                   (order 1)
//   Heun (RK2)     k1 = R(u) + S0,  w = u + dt k1,
//                  v = u + dt/2 (k1 + R(w) + S1)                            (order 2)
//   Rk4 (classical) k1 = R(u) + S0,  k2 = R(u + dt/2 k1) + Sm,  k3 = R(u + dt/2 k2) + Sm,
//                  k4 = R(u + dt k3) + S1,  v = u + dt/6 (k1 + 2 k2 + 2 k3 + k4),
//                  Sm = (S0 + S1)/2       (order 4; 2 where S is not linear in t over a step)
//   BackwardEuler  F(v) = v - u - dt (R(v) + S1)                      = 0  (order 1, L-stable)
//   Trapezoidal    F(v) = v - u - dt/2 (R(u) + S0 + R(v) + S1)        = 0  (order 2, A-stable)
// The implicit rules are the per-cell "implicit update rules" of the stable-ARD paper
// (Appendix A); instead of eliminating one species by hand per model, the 1..16-species system is
// solved by Newton with the model's analytic Jacobian,
//   J_F = I - c dt dR/du(v),  c = 1 (BackwardEuler) or 1/2 (Trapezoidal),
// factored by a dense LU with partial pivoting (stack arrays sized by the number of species, at
// most 16).
//
// Newton start: the explicit Euler predictor v0 = u + dt R(u) + dt (c S1 + (1 - c) S0) or u
// itself, whichever has the smaller max-norm residual (a non-finite predictor loses).
// Damping: while the update is large (||dv||_inf > sqrt(tol) scale) and the full step does not
// decrease ||F||_2^2 by the Armijo factor (1 - 2e-4 lambda), the step is halved (at most 10
// times); if no fraction helps, the full step is taken. Near the root this is plain Newton
// (quadratic); far from it, it roughly halves the failures of undamped Newton at dt >> 1/||J||.
// Convergence (scale-aware, affine-invariant): with scale = 1 + max(||u||_inf, ||v||_inf), for
// the full (undamped) update dv that gave v from v', the full update dv' before it (if any) and
// A = J_F(v'), the matrix of that update,
//   converged  <=>  ||dv||_inf <= tol * scale, or 2 ||A^-1 F(v)||_inf <= tol * scale, or
//                   theta / (1 - theta) ||dv||_inf <= tol * scale,  theta = ||dv|| / ||dv'|| < 1.
// A^-1 F(v) is the next (simplified) Newton update, from the factors already at hand: to first
// order the error left in v, so the test needs no confirming iteration. The third test
// (Hairer-Wanner's estimate, which assumes linear convergence and in the quadratic regime
// overestimates the error by 1/theta; before the second test existed it took one more
// iteration than needed in about half the cells of a trapezoidal step at dt ||J|| ~ 0.5) still
// stops a solve whose updates have reached the round-off floor above a tiny tol. The returned v
// is within tol * scale of a solve at tol 1e-16 for every model at dt ||J|| = 0.3, 1, 3
// (tests/integrators/test_reaction_kernel.cpp).
// The "1 +" makes tol absolute for concentrations below 1 and relative above. The residual
// ||F(v)||_inf is reported but not tested: for large dt, F ~ dt R(v) carries round-off of order eps
// dt |terms of R|, which can exceed any fixed tolerance on F although v is exact to working
// precision (a stiff cell), while the update stays a faithful error measure. tol should be well
// above machine epsilon (1e-13 or more); an exact zero residual at the start is accepted with 0
// iterations. Failure (converged = false; nothing is thrown, nothing is divided by zero): a
// non-finite input, residual or iterate, a (numerically) singular J_F (|pivot| <= eps ||J_F||_inf),
// or no convergence within maxit iterations (maxit < 1: only the predictor is evaluated). v then
// holds the last iterate. iterations counts LU solves. Explicit schemes report iterations = 0,
// residual = 0 and converged = all outputs finite. Undamped or damped, Newton is local: for
// dt >> 1/||J|| it fails from a few % of states (the caller should retry with a smaller dt).
//
// reaction_row applies reaction_cell to the n cells of a row (species rows u[s][i], parameters
// as scalars or, FieldParams = true, as per-cell rows), clamps out_s = max(v_s, floor_s) (floor
// 0 or -inf), and returns -1 when every cell converged (then *worst = {max iterations, max
// residual, true}) or the index i of the first failed cell (then *worst = that cell's CellSolve,
// cells [0, i) are written and cells [i, n) are left untouched). out may alias u (in place):
// each cell's inputs are read before its outputs are written.
#pragma once

#include "fields/clamp_kernel.hpp"

#include <cmath>
#include <limits>

namespace morphogen {

enum class ReactionScheme { Euler, Heun, Rk4, BackwardEuler, Trapezoidal };

struct CellSolve {
  int iterations = 0;    // Newton iterations (LU solves); 0 for explicit schemes
  double residual = 0.0; // max-norm of F at the returned v (0 for explicit schemes)
  bool converged = false;
};

namespace detail {

constexpr int kMaxSpecies = 16;
constexpr int kMaxHalvings = 10; // Newton damping: smallest step fraction 2^-10

template <int N> inline double max_abs(const double* x) {
  double m = 0.0;
  for (int s = 0; s < N; ++s) {
    const double a = std::fabs(x[s]);
    if (a > m || std::isnan(a)) m = a; // a NaN entry makes (and keeps) the result NaN
  }
  return m;
}

template <int N> inline double sum_sq(const double* x) {
  double m = 0.0;
  for (int s = 0; s < N; ++s)
    m += x[s] * x[s];
  return m;
}

// Convergence scale 1 + max(||u||_inf, ||v||_inf).
template <int N> inline double scale(double unorm, const double* v) {
  const double vn = max_abs<N>(v);
  return 1.0 + (unorm > vn ? unorm : vn);
}

template <int N> inline bool all_finite(const double* x) {
  for (int s = 0; s < N; ++s)
    if (!std::isfinite(x[s])) return false;
  return true;
}

// Factors P A = L U in place (A: N x N row-major; L's multipliers below the diagonal, U on and
// above it; piv[k]: the row swapped with row k at step k) by Gaussian elimination with partial
// pivoting. Returns false when a pivot is not finite or |pivot| <= eps ||A||_inf (numerically
// singular).
template <int N> inline bool lu_factor(double* A, int* piv) {
  double norm = 0.0;
  for (int r = 0; r < N; ++r) {
    double row = 0.0;
    for (int c = 0; c < N; ++c)
      row += std::fabs(A[r * N + c]);
    if (row > norm || std::isnan(row)) norm = row;
  }
  if (!std::isfinite(norm) || !(norm > 0.0)) return false;
  const double tiny = std::numeric_limits<double>::epsilon() * norm;
  for (int k = 0; k < N; ++k) {
    int p = k;
    double big = std::fabs(A[k * N + k]);
    for (int r = k + 1; r < N; ++r) {
      const double a = std::fabs(A[r * N + k]);
      if (a > big) {
        big = a;
        p = r;
      }
    }
    if (!(big > tiny) || !std::isfinite(big)) return false;
    piv[k] = p;
    if (p != k)
      for (int c = 0; c < N; ++c) {
        const double t = A[k * N + c];
        A[k * N + c] = A[p * N + c];
        A[p * N + c] = t;
      }
    const double inv = 1.0 / A[k * N + k];
    for (int r = k + 1; r < N; ++r) {
      const double f = A[r * N + k] * inv;
      A[r * N + k] = f;
      if (f == 0.0) continue;
      for (int c = k + 1; c < N; ++c)
        A[r * N + c] -= f * A[k * N + c];
    }
  }
  return true;
}

// b <- A^-1 b from lu_factor's A and piv (the same operations, in the same order, as an
// elimination that carried b along).
template <int N> inline void lu_apply(const double* A, const int* piv, double* b) {
  for (int k = 0; k < N; ++k) {
    if constexpr (N > 1) // (one unknown: no swaps)
      if (piv[k] != k) {
        const double t = b[k];
        b[k] = b[piv[k]];
        b[piv[k]] = t;
      }
    for (int r = k + 1; r < N; ++r) {
      const double f = A[r * N + k];
      if (f != 0.0) b[r] -= f * b[k];
    }
  }
  for (int k = N - 1; k >= 0; --k) {
    double x = b[k];
    for (int c = k + 1; c < N; ++c)
      x -= A[k * N + c] * b[c];
    b[k] = x / A[k * N + k];
  }
}

// The convergence test of the header comment after a full Newton update of size `step`, the
// full update before it `prev` (0: none), next = ||A^-1 F(v)||_inf for the new iterate v and the
// matrix A of that update, and bound = tol * scale; branch-free (the lockstep kernel applies its
// first two tests per lane, newton_update_converged_mask): step <= bound, or 2 next <= bound, or
// step^2 <= (prev - step) bound, which for prev > 0 is theta / (1 - theta) step <= bound with
// theta = step / prev < 1.
inline double newton_update_converged_mask(double step, double next, double bound) {
  return step <= bound || 2.0 * next <= bound ? 1.0 : 0.0;
}

inline double newton_converged_mask(double step, double prev, double next, double bound) {
  const double plain = newton_update_converged_mask(step, next, bound);
  const double estimate = step * step <= (prev - step) * bound ? 1.0 : 0.0;
  return plain > estimate ? plain : estimate;
}

inline bool newton_converged(double step, double prev, double next, double bound) {
  return newton_converged_mask(step, prev, next, bound) != 0.0;
}

// The explicit schemes (Euler, Heun, Rk4) for one cell, given ru = R(u); s0, s1 the sources
// (zeros where none). Shared by the per-cell solver and the vectorised rows
// (reaction_explicit_kernel.hpp), which inline it per lane.
template <ReactionScheme S, int NS, class Model>
inline void explicit_cell(const Model& m, const double* u, const double* p, const double* ru,
                          const double* s0, const double* s1, double dt, double* v) {
  double k[NS], w[NS], r[NS];
#pragma GCC unroll 16
  for (int q = 0; q < NS; ++q) {
    k[q] = ru[q] + s0[q];
    w[q] = u[q] + (S == ReactionScheme::Rk4 ? 0.5 * dt : dt) * k[q];
  }
  if constexpr (S == ReactionScheme::Euler) {
#pragma GCC unroll 16
    for (int q = 0; q < NS; ++q)
      v[q] = w[q];
  } else if constexpr (S == ReactionScheme::Heun) {
    m.rates(w, p, r);
#pragma GCC unroll 16
    for (int q = 0; q < NS; ++q)
      v[q] = u[q] + 0.5 * dt * (k[q] + r[q] + s1[q]);
  } else {
    static_assert(S == ReactionScheme::Rk4, "explicit_cell: Euler, Heun or Rk4");
    double acc[NS], sm[NS];
    const double c[3] = {0.5 * dt, dt, 0.0}; // the next stage's offset after k2, k3, k4
#pragma GCC unroll 16
    for (int q = 0; q < NS; ++q) {
      acc[q] = k[q];
      sm[q] = 0.5 * (s0[q] + s1[q]);
    }
#pragma GCC unroll 4
    for (int stage = 0; stage < 3; ++stage) {
      m.rates(w, p, r);
#pragma GCC unroll 16
      for (int q = 0; q < NS; ++q) {
        k[q] = r[q] + (stage == 2 ? s1[q] : sm[q]);
        acc[q] += (stage == 2 ? 1.0 : 2.0) * k[q];
        w[q] = u[q] + c[stage] * k[q];
      }
    }
#pragma GCC unroll 16
    for (int q = 0; q < NS; ++q)
      v[q] = u[q] + dt / 6.0 * acc[q];
  }
}

} // namespace detail

// One cell: see the header comment. u, S0, S1 and v have M::nspecies entries (S0/S1 may be
// nullptr for a zero source), p has M::nparams. v must not alias u.
// reaction_cell_of is the same for a model object m whose rates(u, p, r) and jacobian(u, p, J)
// may carry state (a model built at run time); NS is its number of species.
template <int NS, class Model>
inline CellSolve reaction_cell_of(const Model& m, ReactionScheme scheme, const double* u,
                                  const double* p, const double* S0, const double* S1, double dt,
                                  double tol, int maxit, double* v) {
  static_assert(NS >= 1 && NS <= detail::kMaxSpecies, "reaction_cell: 1..16 species");
  double s0[NS], s1[NS], ru[NS];
  for (int s = 0; s < NS; ++s) {
    s0[s] = S0 ? S0[s] : 0.0;
    s1[s] = S1 ? S1[s] : 0.0;
  }
  m.rates(u, p, ru);
  CellSolve out{0, 0.0, false};

  if (scheme == ReactionScheme::Euler || scheme == ReactionScheme::Heun ||
      scheme == ReactionScheme::Rk4) {
    if (scheme == ReactionScheme::Euler)
      detail::explicit_cell<ReactionScheme::Euler, NS>(m, u, p, ru, s0, s1, dt, v);
    else if (scheme == ReactionScheme::Heun)
      detail::explicit_cell<ReactionScheme::Heun, NS>(m, u, p, ru, s0, s1, dt, v);
    else
      detail::explicit_cell<ReactionScheme::Rk4, NS>(m, u, p, ru, s0, s1, dt, v);
    out.converged = detail::all_finite<NS>(v);
    return out;
  }

  // Implicit: F(v) = v - base - c dt (R(v) + S1), base = u (+ dt/2 (R(u) + S0) for TR).
  const bool trap = scheme == ReactionScheme::Trapezoidal;
  const double cdt = trap ? 0.5 * dt : dt;
  double base[NS], pred[NS], F[NS], r[NS];
  for (int s = 0; s < NS; ++s) {
    base[s] = trap ? u[s] + cdt * (ru[s] + s0[s]) : u[s];
    pred[s] = base[s] + cdt * (ru[s] + s1[s]); // explicit Euler predictor
  }
  const double unorm = detail::max_abs<NS>(u);
  auto residual = [&](const double* x, double* f) {
    m.rates(x, p, r);
    for (int s = 0; s < NS; ++s)
      f[s] = x[s] - base[s] - cdt * (r[s] + s1[s]);
    return detail::max_abs<NS>(f);
  };
  // F(u) = u - pred exactly (algebraically), so the start u costs no rates() call.
  double Fu[NS];
  for (int s = 0; s < NS; ++s)
    Fu[s] = u[s] - pred[s];
  const double res_u = detail::max_abs<NS>(Fu);
  double res = residual(pred, F);
  if (res < res_u) { // false when res is NaN: the predictor loses
    for (int s = 0; s < NS; ++s)
      v[s] = pred[s];
  } else {
    res = res_u;
    for (int s = 0; s < NS; ++s) {
      v[s] = u[s];
      F[s] = Fu[s];
    }
  }
  out.residual = res;
  if (!std::isfinite(res) || !std::isfinite(unorm)) return out;
  if (res == 0.0) {
    out.converged = true;
    return out;
  }

  // Newton; the step is damped (halved up to kMaxHalvings times) only while it is large and
  // the full step does not decrease ||F||_2 (Armijo); if no halving helps, the full step is
  // taken, so this is never worse than plain Newton, and near the root it is plain Newton.
  double J[NS * NS], dv[NS], vt[NS], Ft[NS];
  const double big_step = std::sqrt(tol);
  double prev = 0.0; // the previous full update's size (0: none)
  int piv[NS];
  for (int it = 1; it <= maxit; ++it) {
    m.jacobian(v, p, J);
    for (int q = 0; q < NS * NS; ++q)
      J[q] *= -cdt;
    for (int s = 0; s < NS; ++s) {
      J[s * NS + s] += 1.0;
      dv[s] = -F[s];
    }
    out.iterations = it;
    if (!detail::lu_factor<NS>(J, piv)) return out;
    detail::lu_apply<NS>(J, piv, dv);
    const double step = detail::max_abs<NS>(dv);
    const bool far = step > big_step * detail::scale<NS>(unorm, v);
    const double f2 = detail::sum_sq<NS>(F);
    double lam = 1.0;
    for (int halvings = 0;; ++halvings) {
      for (int s = 0; s < NS; ++s)
        vt[s] = v[s] + lam * dv[s];
      res = residual(vt, Ft);
      if (!far) break;
      if (std::isfinite(res) && detail::sum_sq<NS>(Ft) <= (1.0 - 2e-4 * lam) * f2) break;
      if (halvings == detail::kMaxHalvings) { // no decrease: fall back to the full step
        lam = 1.0;
        for (int s = 0; s < NS; ++s)
          vt[s] = v[s] + dv[s];
        res = residual(vt, Ft);
        break;
      }
      lam *= 0.5;
    }
    for (int s = 0; s < NS; ++s) {
      v[s] = vt[s];
      F[s] = Ft[s];
    }
    out.residual = res;
    if (!std::isfinite(res)) return out; // also catches a non-finite v (F contains v)
    if (lam == 1.0) {
      double ahead[NS]; // A^-1 F(v): about the error left in v
      for (int s = 0; s < NS; ++s)
        ahead[s] = -F[s];
      detail::lu_apply<NS>(J, piv, ahead);
      const double next = detail::max_abs<NS>(ahead);
      if (detail::newton_converged(step, prev, next, tol * detail::scale<NS>(unorm, v))) {
        out.converged = true;
        return out;
      }
    }
    prev = lam == 1.0 ? step : 0.0;
  }
  return out;
}

template <class M>
inline CellSolve reaction_cell(ReactionScheme scheme, const double* u, const double* p,
                               const double* S0, const double* S1, double dt, double tol, int maxit,
                               double* v) {
  return reaction_cell_of<M::nspecies>(M{}, scheme, u, p, S0, S1, dt, tol, maxit, v);
}

// One row of n cells: see the header comment. u, S0, S1 and out are [NS] row pointers (S0/S1
// nullptr for a zero source), prow [np] parameter rows (FieldParams) or pconst [np] scalars,
// floor [NS] lower clamps. worst may be nullptr. reaction_row_of takes a model object m with
// NS species and np <= NPMax parameters; reaction_row<M, FieldParams> is it for a model type.
template <int NS, int NPMax, bool FieldParams, class Model>
inline int reaction_row_of(const Model& m, int np, ReactionScheme scheme, int n,
                           const double* const* u, const double* const* prow, const double* pconst,
                           const double* const* S0, const double* const* S1, double dt, double tol,
                           int maxit, const double* floor, double* const* out, CellSolve* worst) {
  static_assert(NS >= 1 && NS <= detail::kMaxSpecies, "reaction_row: 1..16 species");
  double p[NPMax > 0 ? NPMax : 1] = {};
  if constexpr (!FieldParams)
    for (int q = 0; q < np; ++q)
      p[q] = pconst[q];
  CellSolve acc{0, 0.0, true};
  for (int i = 0; i < n; ++i) {
    double uc[NS], a[NS], b[NS], v[NS];
    if constexpr (FieldParams)
      for (int q = 0; q < np; ++q)
        p[q] = prow[q][i];
    for (int s = 0; s < NS; ++s) {
      uc[s] = u[s][i];
      if (S0) a[s] = S0[s][i];
      if (S1) b[s] = S1[s][i];
    }
    const CellSolve cs = reaction_cell_of<NS>(m, scheme, uc, p, S0 ? a : nullptr, S1 ? b : nullptr,
                                              dt, tol, maxit, v);
    if (!cs.converged) {
      if (worst) *worst = cs;
      return i;
    }
    if (cs.iterations > acc.iterations) acc.iterations = cs.iterations;
    if (cs.residual > acc.residual) acc.residual = cs.residual;
    for (int s = 0; s < NS; ++s)
      out[s][i] = clamp_to_floor(v[s], floor[s]);
  }
  if (worst) *worst = acc;
  return -1;
}

template <class M, bool FieldParams>
inline int reaction_row(ReactionScheme scheme, int n, const double* const* u,
                        const double* const* prow, const double* pconst, const double* const* S0,
                        const double* const* S1, double dt, double tol, int maxit,
                        const double* floor, double* const* out, CellSolve* worst) {
  return reaction_row_of<M::nspecies, M::nparams, FieldParams>(
      M{}, M::nparams, scheme, n, u, prow, pconst, S0, S1, dt, tol, maxit, floor, out, worst);
}

} // namespace morphogen
