// Unit tests of the per-cell reaction kernels (integrators/reaction_kernel.hpp; serial, pure
// header code, no MPI or PETSc):
//   1. every model: BackwardEuler and Trapezoidal converge in <= 8 Newton iterations near the
//      default steady state at dt = 0.1 / ||J||_inf, and v satisfies F(v) = 0 (checked here with
//      M::rates, independently of the kernel's residual);
//   2. Newton converges quadratically (Gray-Scott, a stiff step);
//   3. orders of accuracy 1, 2, 2, 1, 2 (Euler, Heun, Rk4, BackwardEuler, Trapezoidal) on
//      du/dt = R(u) + S(t) for Schnakenberg and Turing against an RK4 reference (Rk4's
//      mid-step source (S0 + S1)/2 is second order in S), and 4 for Rk4 without a source;
//   4. BackwardEuler on Turing's model reproduces the stable-ARD paper's Appendix A update rule
//      (with the factor s on the 16 dt term that the paper's typesetting lost);
//   5. failures (NaN input, overflow, singular Jacobian, Newton that does not converge) are
//      reported, by reaction_row with the failing cell's index; in-place equals out-of-place.
#include "../model_typed_tests.hpp"
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "integrators/reaction_kernel.hpp"
#include "models/all_models.hpp"

namespace {

using namespace morphogen;
namespace mm = morphogen::models;

constexpr ReactionScheme kAllSchemes[] = {ReactionScheme::Euler, ReactionScheme::Heun,
                                          ReactionScheme::Rk4, ReactionScheme::BackwardEuler,
                                          ReactionScheme::Trapezoidal};
const char* scheme_name(ReactionScheme s) {
  switch (s) {
  case ReactionScheme::Euler:
    return "Euler";
  case ReactionScheme::Heun:
    return "Heun";
  case ReactionScheme::Rk4:
    return "Rk4";
  case ReactionScheme::BackwardEuler:
    return "BackwardEuler";
  case ReactionScheme::Trapezoidal:
    return "Trapezoidal";
  }
  return "?";
}

template <class M> using State = std::array<double, M::nspecies>;

template <class M> std::array<double, M::nparams> defaults() {
  std::array<double, M::nparams> p{};
  for (int i = 0; i < M::nparams; ++i)
    p[i] = M::params[i].def;
  return p;
}

template <int N> double max_abs(const std::array<double, N>& x) {
  double m = 0.0;
  for (double a : x)
    m = std::max(m, std::fabs(a));
  return m;
}

// ||dR/du(u)||_inf.
template <class M> double jacobian_norm(const double* u, const double* p) {
  constexpr int NS = M::nspecies;
  double J[NS * NS];
  M::jacobian(u, p, J);
  double norm = 0.0;
  for (int r = 0; r < NS; ++r) {
    double row = 0.0;
    for (int c = 0; c < NS; ++c)
      row += std::fabs(J[r * NS + c]);
    norm = std::max(norm, row);
  }
  return norm;
}

// The defining residual of the implicit schemes, computed here from M::rates alone:
//   BackwardEuler  F = v - u - dt (R(v) + S1)
//   Trapezoidal    F = v - u - dt/2 (R(u) + S0 + R(v) + S1)
template <class M>
State<M> implicit_residual(ReactionScheme scheme, const State<M>& u, const double* p,
                           const State<M>& S0, const State<M>& S1, double dt, const State<M>& v) {
  State<M> ru, rv, F;
  M::rates(u.data(), p, ru.data());
  M::rates(v.data(), p, rv.data());
  for (int s = 0; s < M::nspecies; ++s) {
    if (scheme == ReactionScheme::BackwardEuler)
      F[s] = v[s] - u[s] - dt * (rv[s] + S1[s]);
    else
      F[s] = v[s] - u[s] - 0.5 * dt * (ru[s] + S0[s] + rv[s] + S1[s]);
  }
  return F;
}

// ---------------------------------------------------------------------------------------------
// 1. Every model near its steady state.

MG_MODEL_TYPED_TEST_SUITE(ReactionKernelModels);

TYPED_TEST(ReactionKernelModels, ImplicitSchemesConvergeNearTheSteadyState) {
  using M = TypeParam;
  constexpr int NS = M::nspecies;
  const auto p = defaults<M>();
  State<M> ustar;
  if (!M::steady_state(p.data(), ustar.data()))
    for (int s = 0; s < NS; ++s)
      ustar[s] = M::species[s].init;
  // Perturb by a few per cent (+4%, -3%, ...) plus 0.005 so that zero components move too.
  State<M> u;
  for (int s = 0; s < NS; ++s)
    u[s] = ustar[s] * (1.0 + (s % 2 == 0 ? 0.04 : -0.03)) + 0.005;
  const double jn = jacobian_norm<M>(u.data(), p.data());
  ASSERT_GT(jn, 0.0);
  const double dt = 0.1 / jn;
  // Without a source, and with a start/end source of a few per cent of the state per unit
  // reaction time (so that dt S is comparable to dt R).
  State<M> zero{}, S0, S1;
  for (int s = 0; s < NS; ++s) {
    S0[s] = 0.02 * jn * (std::fabs(ustar[s]) + 0.01);
    S1[s] = -0.5 * S0[s];
  }
  const double tol = 1e-12;
  for (bool with_source : {false, true}) {
    const State<M>& a = with_source ? S0 : zero;
    const State<M>& b = with_source ? S1 : zero;
    for (ReactionScheme scheme : {ReactionScheme::BackwardEuler, ReactionScheme::Trapezoidal}) {
      SCOPED_TRACE(std::string(scheme_name(scheme)) + (with_source ? " with source" : ""));
      State<M> v;
      const CellSolve cs =
          reaction_cell<M>(scheme, u.data(), p.data(), with_source ? a.data() : nullptr,
                           with_source ? b.data() : nullptr, dt, tol, 50, v.data());
      EXPECT_TRUE(cs.converged);
      EXPECT_LE(cs.iterations, 8);
      const double scale = 1.0 + std::max(max_abs<NS>(u), max_abs<NS>(v));
      EXPECT_LT(cs.residual, 1e-12 * scale);
      const State<M> F = implicit_residual<M>(scheme, u, p.data(), a, b, dt, v);
      EXPECT_LT(max_abs<NS>(F), 1e-12 * scale);
      EXPECT_NEAR(max_abs<NS>(F), cs.residual, 1e-14 * scale); // the kernel reports F(v)
      // The step really moved the state (the check above is not vacuous).
      double moved = 0.0;
      for (int s = 0; s < NS; ++s)
        moved = std::max(moved, std::fabs(v[s] - u[s]));
      EXPECT_GT(moved, 1e-6 * dt);
    }
  }
}

TYPED_TEST(ReactionKernelModels, ExplicitSchemesMatchTheirFormulas) {
  using M = TypeParam;
  constexpr int NS = M::nspecies;
  const auto p = defaults<M>();
  State<M> u, S0, S1, k1, w, rw, v;
  for (int s = 0; s < NS; ++s) {
    u[s] = M::species[s].init * 1.1 + 0.01 * (s + 1);
    S0[s] = 0.01 * (s + 1);
    S1[s] = -0.02 * (s + 1);
  }
  const double dt = 0.1 / std::max(jacobian_norm<M>(u.data(), p.data()), 1e-3);
  M::rates(u.data(), p.data(), k1.data());
  CellSolve cs = reaction_cell<M>(ReactionScheme::Euler, u.data(), p.data(), S0.data(), S1.data(),
                                  dt, 1e-12, 10, v.data());
  EXPECT_TRUE(cs.converged);
  EXPECT_EQ(cs.iterations, 0);
  for (int s = 0; s < NS; ++s) {
    EXPECT_DOUBLE_EQ(v[s], u[s] + dt * (k1[s] + S0[s]));
    k1[s] += S0[s];
    w[s] = u[s] + dt * k1[s];
  }
  M::rates(w.data(), p.data(), rw.data());
  cs = reaction_cell<M>(ReactionScheme::Heun, u.data(), p.data(), S0.data(), S1.data(), dt, 1e-12,
                        10, v.data());
  EXPECT_TRUE(cs.converged);
  EXPECT_EQ(cs.iterations, 0);
  for (int s = 0; s < NS; ++s)
    EXPECT_DOUBLE_EQ(v[s], u[s] + 0.5 * dt * (k1[s] + rw[s] + S1[s]));
}

// ---------------------------------------------------------------------------------------------
// 2. Quadratic convergence of Newton. The k-th iterate (k < the iterations the converged solve
// took) is the result of the same solve with maxit = k, so the iterates are observable without
// instrumentation; k = 0 is the start (predictor or u).

TEST(ReactionKernelNewton, ConvergesQuadraticallyOnGrayScott) {
  using M = mm::GrayScott;
  const auto p = defaults<M>();
  const double u[2] = {0.25, 0.5};
  const double dt = 10.0; // about 1 / ||J||: the Euler predictor is far off
  for (ReactionScheme scheme : {ReactionScheme::BackwardEuler, ReactionScheme::Trapezoidal}) {
    SCOPED_TRACE(scheme_name(scheme));
    double vstar[2];
    const CellSolve cs =
        reaction_cell<M>(scheme, u, p.data(), nullptr, nullptr, dt, 1e-14, 50, vstar);
    ASSERT_TRUE(cs.converged);
    std::vector<double> err;
    ASSERT_GE(cs.iterations, 3);
    for (int k = 0; k < cs.iterations; ++k) {
      double v[2];
      EXPECT_FALSE(
          reaction_cell<M>(scheme, u, p.data(), nullptr, nullptr, dt, 1e-14, k, v).converged);
      err.push_back(std::max(std::fabs(v[0] - vstar[0]), std::fabs(v[1] - vstar[1])));
    }
    std::printf("  Gray-Scott %-13s Newton errors:", scheme_name(scheme));
    for (double e : err)
      std::printf(" %.2e", e);
    std::printf("\n");
    // Quadratic: e_{k+1} <= C e_k^2 while above round-off (measured C = 3.5..6 for BE), and at
    // least two such steps seen. A linear rate would fail this once e_k is below 1e-3.
    int checked = 0;
    for (std::size_t k = 0; k + 1 < err.size(); ++k) {
      if (err[k] > 0.2 || err[k + 1] < 1e-14) continue;
      EXPECT_LE(err[k + 1], 10.0 * err[k] * err[k]) << "iteration " << k + 1;
      ++checked;
    }
    EXPECT_GE(checked, 2);
    // The returned v is accurate to the tolerance (the last update, or the error it predicts
    // from the contraction, was <= 1e-14 (1 + |v|)): against a solve at tol 1e-16.
    double vref[2];
    ASSERT_TRUE(
        reaction_cell<M>(scheme, u, p.data(), nullptr, nullptr, dt, 1e-16, 50, vref).converged);
    const double scale = 1.0 + std::max(std::fabs(vstar[0]), std::fabs(vstar[1]));
    EXPECT_LE(std::max(std::fabs(vstar[0] - vref[0]), std::fabs(vstar[1] - vref[1])),
              1e-14 * scale);
  }
}

// The stopping rule: the next-update estimate 2 ||A^-1 F(v)|| <= tol scale stops Newton no later
// than the update tests alone (||dv|| or theta / (1 - theta) ||dv|| <= tol scale, applied here
// to the updates between the observable iterates: the solve with maxit = k), and earlier in a
// good share of the cells (Brusselator, trapezoidal, the deck's reaction half-step dt 0.125, cells
// +-30 % around the steady state).
TEST(ReactionKernelNewton, NextUpdateEstimateSavesAnIteration) {
  using M = mm::Brusselator;
  const auto p = defaults<M>();
  const double tol = 1e-12, dt = 0.125;
  int earlier = 0, cells = 0;
  for (int c = 0; c < 50; ++c) {
    const double u[2] = {3.0 * (1.0 + 0.3 * std::sin(0.37 * c)),
                         3.0 * (1.0 - 0.3 * std::sin(0.37 * c + 0.5))};
    double v[2];
    const CellSolve cs = reaction_cell<M>(ReactionScheme::Trapezoidal, u, p.data(), nullptr,
                                          nullptr, dt, tol, 20, v);
    ASSERT_TRUE(cs.converged);
    double prev_v[2], prev = 0.0;
    reaction_cell<M>(ReactionScheme::Trapezoidal, u, p.data(), nullptr, nullptr, dt, tol, 0,
                     prev_v);
    int k_update = 0; // where the update tests alone stop
    for (int k = 1; k <= 20 && k_update == 0; ++k) {
      double vk[2];
      reaction_cell<M>(ReactionScheme::Trapezoidal, u, p.data(), nullptr, nullptr, dt, 1e-300, k,
                       vk);
      const double step = std::max(std::fabs(vk[0] - prev_v[0]), std::fabs(vk[1] - prev_v[1]));
      const double bound =
          tol *
          (1.0 + std::max({std::fabs(u[0]), std::fabs(u[1]), std::fabs(vk[0]), std::fabs(vk[1])}));
      if (step <= bound || step * step <= (prev - step) * bound) k_update = k;
      prev = step;
      prev_v[0] = vk[0];
      prev_v[1] = vk[1];
    }
    ASSERT_GT(k_update, 0);
    EXPECT_LE(cs.iterations, k_update) << "cell " << c;
    earlier += cs.iterations < k_update;
    ++cells;
  }
  std::printf("  Brusselator trapezoidal dt 0.125: %d of %d cells stop an iteration earlier\n",
              earlier, cells);
  EXPECT_GE(earlier, cells / 4);
}

// Every model, BackwardEuler and Trapezoidal, cells +-30 % around the default initial state, dt
// = 0.3, 1 and 3 / ||J||_inf, tol 1e-12 and 1e-10: the returned v is within tol (1 + |v|) of the
// root (a solve at tol 1e-16), whichever test stopped it.
TYPED_TEST(ReactionKernelModels, ConvergedCellsAreWithinTheTolerance) {
  using M = TypeParam;
  constexpr int NS = M::nspecies;
  const auto p = defaults<M>();
  int checked = 0;
  for (int c = 0; c < 40; ++c) {
    State<M> u, v, vref;
    for (int s = 0; s < NS; ++s)
      u[s] = M::species[s].init * (1.0 + 0.3 * std::sin(0.7 * c + 1.3 * s)) + 0.01 * (s + 1);
    const double jn = std::max(jacobian_norm<M>(u.data(), p.data()), 1e-3);
    for (double f : {0.3, 1.0, 3.0})
      for (ReactionScheme scheme : {ReactionScheme::BackwardEuler, ReactionScheme::Trapezoidal})
        for (double tol : {1e-12, 1e-10}) {
          const double dt = f / jn;
          if (!reaction_cell<M>(scheme, u.data(), p.data(), nullptr, nullptr, dt, 1e-16, 60,
                                vref.data())
                   .converged ||
              !reaction_cell<M>(scheme, u.data(), p.data(), nullptr, nullptr, dt, tol, 60, v.data())
                   .converged)
            continue;
          const double scale = 1.0 + std::max(max_abs<NS>(u), max_abs<NS>(vref));
          double err = 0.0;
          for (int s = 0; s < NS; ++s)
            err = std::max(err, std::fabs(v[s] - vref[s]));
          EXPECT_LE(err, tol * scale) << "cell " << c << " dt " << dt << " tol " << tol;
          ++checked;
        }
  }
  EXPECT_GE(checked, 200);
}

// ---------------------------------------------------------------------------------------------
// 3. Order of accuracy on du/dt = R(u) + S(t).

template <class M> struct OrderCase;
template <> struct OrderCase<mm::Schnakenberg> {
  static constexpr double T = 2.0;
  static constexpr std::array<double, 2> u0{0.5, 1.5}; // steady state is (1, 0.9)
  static std::array<double, 2> source(double t) {
    return {0.2 * std::sin(3.0 * t), 0.1 * std::cos(2.0 * t)};
  }
};
template <> struct OrderCase<mm::Turing> {
  // s = 1/128: one reaction time is 128 time units.
  static constexpr double T = 128.0;
  // Steady state (4, 4), a stable focus; without clamping, states far below it (e.g. (2, 3))
  // run to a < 0 and blow up, so start nearby.
  static constexpr std::array<double, 2> u0{4.6, 3.6};
  static std::array<double, 2> source(double t) {
    return {0.01 * std::sin(t / 16.0), -0.005 * std::cos(t / 32.0)};
  }
};

template <class M>
std::array<double, 2> rhs(const std::array<double, 2>& u, const double* p, double t) {
  std::array<double, 2> r;
  M::rates(u.data(), p, r.data());
  const auto S = OrderCase<M>::source(t);
  return {r[0] + S[0], r[1] + S[1]};
}

template <class M> std::array<double, 2> rk4_reference(const double* p, int n) {
  const double T = OrderCase<M>::T, h = T / n;
  auto u = OrderCase<M>::u0;
  for (int i = 0; i < n; ++i) {
    const double t = i * h;
    std::array<double, 2> k1 = rhs<M>(u, p, t), k2, k3, k4, w;
    for (int s = 0; s < 2; ++s)
      w[s] = u[s] + 0.5 * h * k1[s];
    k2 = rhs<M>(w, p, t + 0.5 * h);
    for (int s = 0; s < 2; ++s)
      w[s] = u[s] + 0.5 * h * k2[s];
    k3 = rhs<M>(w, p, t + 0.5 * h);
    for (int s = 0; s < 2; ++s)
      w[s] = u[s] + h * k3[s];
    k4 = rhs<M>(w, p, t + h);
    for (int s = 0; s < 2; ++s)
      u[s] += h / 6.0 * (k1[s] + 2.0 * k2[s] + 2.0 * k3[s] + k4[s]);
  }
  return u;
}

template <class M>
double kernel_error(ReactionScheme scheme, const double* p, int n,
                    const std::array<double, 2>& ref) {
  const double T = OrderCase<M>::T, dt = T / n;
  auto u = OrderCase<M>::u0;
  for (int i = 0; i < n; ++i) {
    const auto S0 = OrderCase<M>::source(i * dt), S1 = OrderCase<M>::source((i + 1) * dt);
    std::array<double, 2> v;
    const CellSolve cs =
        reaction_cell<M>(scheme, u.data(), p, S0.data(), S1.data(), dt, 1e-14, 30, v.data());
    EXPECT_TRUE(cs.converged) << "step " << i;
    u = v;
  }
  return std::max(std::fabs(u[0] - ref[0]), std::fabs(u[1] - ref[1]));
}

template <class M> void check_orders() {
  const auto p = defaults<M>();
  const auto ref = rk4_reference<M>(p.data(), 200000);
  // Self-check of the reference: halving its step changes it by round-off only.
  const auto ref2 = rk4_reference<M>(p.data(), 100000);
  ASSERT_LT(std::max(std::fabs(ref[0] - ref2[0]), std::fabs(ref[1] - ref2[1])), 1e-12);
  const int n0 = 80;
  for (ReactionScheme scheme : kAllSchemes) {
    // Rk4 takes the source at mid-step as (S0 + S1)/2, which is second order in S(t).
    const bool second = scheme == ReactionScheme::Heun || scheme == ReactionScheme::Trapezoidal ||
                        scheme == ReactionScheme::Rk4;
    // Least-squares slope of log(error) against log(dt) over 5 step sizes (halved 4 times).
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    char line[256];
    int len = 0;
    for (int k = 0; k < 5; ++k) {
      const int n = n0 << k;
      const double e = kernel_error<M>(scheme, p.data(), n, ref);
      const double x = std::log(OrderCase<M>::T / n), y = std::log(e);
      sx += x;
      sy += y;
      sxx += x * x;
      sxy += x * y;
      len += std::snprintf(line + len, sizeof line - len, " %.2e", e);
    }
    const double slope = (5 * sxy - sx * sy) / (5 * sxx - sx * sx);
    std::printf("  %s %-13s order %.3f  errors:%s\n", M::name, scheme_name(scheme), slope, line);
    EXPECT_NEAR(slope, second ? 2.0 : 1.0, 0.1) << M::name << " " << scheme_name(scheme);
  }
}

TEST(ReactionKernelOrder, Schnakenberg) {
  check_orders<mm::Schnakenberg>();
}
TEST(ReactionKernelOrder, Turing) {
  check_orders<mm::Turing>();
}

// Without a source Rk4 is fourth order: Schnakenberg from (0.5, 1.5) to t = 2 in 10..160 steps,
// against 20,000 steps of the same scheme (its error there is below 1e-15).
TEST(ReactionKernelOrder, Rk4IsFourthOrderWithoutSources) {
  using M = mm::Schnakenberg;
  const auto p = defaults<M>();
  auto run = [&](int n) {
    std::array<double, 2> u{0.5, 1.5}, v;
    for (int i = 0; i < n; ++i) {
      EXPECT_TRUE(reaction_cell<M>(ReactionScheme::Rk4, u.data(), p.data(), nullptr, nullptr,
                                   2.0 / n, 1e-12, 20, v.data())
                      .converged);
      u = v;
    }
    return u;
  };
  const auto ref = run(20000);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k < 5; ++k) {
    const auto u = run(10 << k);
    const double e = std::max(std::fabs(u[0] - ref[0]), std::fabs(u[1] - ref[1]));
    const double x = std::log(2.0 / (10 << k)), y = std::log(e);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  EXPECT_NEAR((5 * sxy - sx * sy) / (5 * sxx - sx * sx), 4.0, 0.15);
}

// ---------------------------------------------------------------------------------------------
// 4. The stable-ARD paper, Appendix A, Turing's spot formation equations:
//   RA = s (A B - A - beta_paper),  RB = s (16 - A B)
//   A^ = A + s dt ( (B + 16 dt) / (1 + s A^ dt) A^ - A^ - beta_paper ),
//   B^ = (B + 16 dt) / (1 + s A^ dt).
// In our Turing model R_a = s (a b - a - alpha), R_b = s (beta - a b): alpha = beta_paper and
// beta = 16. Backward Euler of RB is B^ = B + s dt (16 - A^ B^), i.e.
//   B^ (1 + s A^ dt) = B + 16 s dt   =>   B^ = (B + 16 s dt) / (1 + s A^ dt).
// The paper's rule writes 16 dt without the factor s; it is backward Euler only for s = 1 (the
// typesetting, or the derivation, lost the s; Turk's s = 1/128 makes the difference large). We
// test against the derived rule, and show that the literal rule holds for s = 1 only.

// Scalar Newton on the paper's A^ equation with the derived B^(A^), independent of the kernel.
double appendix_a_turing(double A, double B, double alpha, double beta, double s, double dt,
                         bool paper_literal) {
  const double Bnum = paper_literal ? B + beta * dt : B + beta * s * dt;
  double a = A;
  for (int it = 0; it < 100; ++it) {
    const double d = 1.0 + s * a * dt;
    const double g = a - A - s * dt * (Bnum / d * a - a - alpha);
    const double dg = 1.0 - s * dt * (Bnum / (d * d) - 1.0); // d/da (a / (1 + s a dt)) = 1/d^2
    const double step = g / dg;
    a -= step;
    if (std::fabs(step) <= 1e-15 * (1.0 + std::fabs(a))) break;
  }
  return a;
}

TEST(ReactionKernelAppendixA, TuringBackwardEulerMatchesTheClosedFormRule) {
  using M = mm::Turing;
  auto p = defaults<M>(); // alpha = 12 (paper's beta), beta = 16 (paper's 16), s = 1/128
  const double alpha = p[0], beta = p[1];
  ASSERT_EQ(beta, 16.0);
  const double A = 3.5, B = 4.6;
  for (double s : {1.0 / 128.0, 1.0}) {
    p[2] = s;
    for (double sdt : {0.01, 0.1, 0.5}) {
      const double dt = sdt / s;
      SCOPED_TRACE("s = " + std::to_string(s) + ", dt = " + std::to_string(dt));
      const double u[2] = {A, B};
      double v[2];
      const CellSolve cs = reaction_cell<M>(ReactionScheme::BackwardEuler, u, p.data(), nullptr,
                                            nullptr, dt, 1e-14, 50, v);
      ASSERT_TRUE(cs.converged);
      const double Ah = v[0], Bh = v[1];
      // B^ from the derived rule, given our A^, and the paper's A^ rule with that B^.
      const double Bd = (B + beta * s * dt) / (1.0 + s * Ah * dt);
      EXPECT_NEAR(Bh, Bd, 1e-12 * Bh);
      EXPECT_NEAR(Ah, A + s * dt * (Bd * Ah - Ah - alpha), 1e-12 * Ah);
      // The scalar closed-form route gives the same A^.
      EXPECT_NEAR(Ah, appendix_a_turing(A, B, alpha, beta, s, dt, false), 1e-12 * Ah);
      // The literal rule (B + 16 dt) / (1 + s A^ dt) agrees only when s = 1.
      const double Bl = (B + beta * dt) / (1.0 + s * Ah * dt);
      const double Al = appendix_a_turing(A, B, alpha, beta, s, dt, true);
      if (s == 1.0) {
        EXPECT_NEAR(Bh, Bl, 1e-12 * Bh);
        EXPECT_NEAR(Ah, Al, 1e-12 * Ah);
      } else {
        EXPECT_GT(std::fabs(Bl - Bh), 0.5);
        EXPECT_GT(std::fabs(Al - Ah), 0.1);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 5. Failures and the row driver.

TEST(ReactionKernelFailure, NonFiniteInputIsReported) {
  using M = mm::GrayScott;
  const auto p = defaults<M>();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (ReactionScheme scheme : kAllSchemes) {
    SCOPED_TRACE(scheme_name(scheme));
    double v[2];
    for (std::array<double, 2> u : {std::array<double, 2>{nan, 0.5}, {0.2, inf}}) {
      const CellSolve cs =
          reaction_cell<M>(scheme, u.data(), p.data(), nullptr, nullptr, 1.0, 1e-12, 20, v);
      EXPECT_FALSE(cs.converged);
    }
    // NaN in a parameter and in a source.
    const double u[2] = {0.2, 0.5}, pn[3] = {0.04, nan, 1.0}, Sn[2] = {0.0, nan};
    EXPECT_FALSE(reaction_cell<M>(scheme, u, pn, nullptr, nullptr, 1.0, 1e-12, 20, v).converged);
    EXPECT_FALSE(reaction_cell<M>(scheme, u, p.data(), Sn, Sn, 1.0, 1e-12, 20, v).converged);
  }
}

TEST(ReactionKernelFailure, HugeTimeStepOverflowIsReported) {
  // dt = 1e308: the explicit update and dt dR/du overflow to inf; nothing throws.
  using M = mm::Brusselator;
  const auto p = defaults<M>();
  const double u[2] = {2.0, 1.0};
  for (ReactionScheme scheme : kAllSchemes) {
    SCOPED_TRACE(scheme_name(scheme));
    double v[2];
    const CellSolve cs =
        reaction_cell<M>(scheme, u, p.data(), nullptr, nullptr, 1e308, 1e-12, 20, v);
    EXPECT_FALSE(cs.converged);
  }
}

TEST(ReactionKernelFailure, SingularJacobianIsReported) {
  // Gray-Scott at (a, b) = (0.1, 0.7): dR/du = [[0.04, 0.01], [-0.14, -0.05]], so with
  // dt/2 = 50 the Newton matrix I - 50 dR/du = [[-1, -0.5], [7, 3.5]] is singular. The start
  // is u itself (its residual is smaller than the predictor's).
  using M = mm::GrayScott;
  const auto p = defaults<M>();
  const double u[2] = {0.1, 0.7};
  double v[2];
  const CellSolve cs = reaction_cell<M>(ReactionScheme::Trapezoidal, u, p.data(), nullptr, nullptr,
                                        100.0, 1e-12, 20, v);
  EXPECT_FALSE(cs.converged);
  EXPECT_EQ(cs.iterations, 1);
  EXPECT_TRUE(std::isfinite(cs.residual));
}

TEST(ReactionKernelFailure, IterationLimitIsReported) {
  using M = mm::GrayScott;
  const auto p = defaults<M>();
  const double u[2] = {0.25, 0.5};
  double v[2];
  const CellSolve full = reaction_cell<M>(ReactionScheme::BackwardEuler, u, p.data(), nullptr,
                                          nullptr, 10.0, 1e-12, 50, v);
  ASSERT_TRUE(full.converged);
  ASSERT_GE(full.iterations, 3);
  const CellSolve cut = reaction_cell<M>(ReactionScheme::BackwardEuler, u, p.data(), nullptr,
                                         nullptr, 10.0, 1e-12, full.iterations - 1, v);
  EXPECT_FALSE(cut.converged);
  EXPECT_EQ(cut.iterations, full.iterations - 1);
  EXPECT_TRUE(std::isfinite(cut.residual));
  EXPECT_GT(cut.residual, full.residual);
}

// A row of Brusselator cells at a = 0, b = 0..10, with dt = 1e7 (about 1e8 / ||J||): Newton,
// damped or not, fails from some of these states. Every cell the kernel reports converged must
// satisfy the backward Euler equation (R(v) = (v - u) / dt: checked relative to the size of
// the terms of R), and reaction_row must return the first failed cell with its CellSolve.
TEST(ReactionKernelFailure, RowReportsTheFirstFailedCellAtHugeDt) {
  using M = mm::Brusselator;
  const auto p = defaults<M>();
  const double dt = 1e7;
  const int n = 21;
  std::vector<double> a(n), b(n), va(n, -7.0), vb(n, -7.0);
  for (int i = 0; i < n; ++i) {
    a[i] = std::max(0.0, 1.0 - 0.1 * i);
    b[i] = 0.5 * i;
  }
  int first_fail = -1, failures = 0;
  CellSolve first{};
  for (int i = 0; i < n; ++i) {
    const double u[2] = {a[i], b[i]};
    double v[2], r[2];
    const CellSolve cs = reaction_cell<M>(ReactionScheme::BackwardEuler, u, p.data(), nullptr,
                                          nullptr, dt, 1e-12, 50, v);
    if (!cs.converged) {
      ++failures;
      if (first_fail < 0) {
        first_fail = i;
        first = cs;
      }
      continue;
    }
    M::rates(v, p.data(), r);
    const double terms =
        1.0 + std::fabs(p[0]) + (1.0 + p[1]) * std::fabs(v[0]) + v[0] * v[0] * std::fabs(v[1]);
    for (int s = 0; s < 2; ++s)
      EXPECT_LT(std::fabs(r[s] - (v[s] - u[s]) / dt), 1e-12 * terms) << "cell " << i;
  }
  std::printf("  Brusselator BackwardEuler dt = 1e7: %d of %d cells fail, first %d\n", failures, n,
              first_fail);
  ASSERT_GT(failures, 0);
  const double* rows[2] = {a.data(), b.data()};
  double* out[2] = {va.data(), vb.data()};
  const double floor[2] = {-HUGE_VAL, -HUGE_VAL};
  CellSolve worst{};
  const int ret = reaction_row<M, false>(ReactionScheme::BackwardEuler, n, rows, nullptr, p.data(),
                                         nullptr, nullptr, dt, 1e-12, 50, floor, out, &worst);
  EXPECT_EQ(ret, first_fail);
  EXPECT_FALSE(worst.converged);
  EXPECT_EQ(worst.iterations, first.iterations);
  EXPECT_EQ(worst.residual, first.residual);
  // Cells before the failure are written, the failed cell and those after are untouched.
  for (int i = 0; i < n; ++i)
    EXPECT_EQ(va[i] == -7.0, i >= first_fail) << "cell " << i;
}

TEST(ReactionKernelRow, NaNCellIsReportedByIndex) {
  using M = mm::GrayScott;
  const auto p = defaults<M>();
  const int n = 7, bad = 4;
  std::vector<double> a(n), b(n);
  for (int i = 0; i < n; ++i) {
    a[i] = 0.05 * i;
    b[i] = 1.0 - 0.1 * i;
  }
  a[bad] = std::numeric_limits<double>::quiet_NaN();
  for (ReactionScheme scheme : kAllSchemes) {
    SCOPED_TRACE(scheme_name(scheme));
    std::vector<double> va(a), vb(b);
    double* rows[2] = {va.data(), vb.data()};
    const double floor[2] = {0.0, 0.0};
    CellSolve worst{0, 0.0, true};
    const int ret = reaction_row<M, false>(scheme, n, rows, nullptr, p.data(), nullptr, nullptr,
                                           1.0, 1e-12, 20, floor, rows, &worst);
    EXPECT_EQ(ret, bad);
    EXPECT_FALSE(worst.converged);
    EXPECT_TRUE(std::isnan(va[bad])); // untouched
    for (int i = bad + 1; i < n; ++i)
      EXPECT_EQ(va[i], a[i]);
    for (int i = 0; i < bad; ++i) { // updated, clamped at 0
      const double u[2] = {a[i], b[i]};
      double v[2];
      ASSERT_TRUE(
          reaction_cell<M>(scheme, u, p.data(), nullptr, nullptr, 1.0, 1e-12, 20, v).converged);
      EXPECT_EQ(va[i], std::max(v[0], 0.0)) << "cell " << i;
      EXPECT_EQ(vb[i], std::max(v[1], 0.0)) << "cell " << i;
    }
  }
}

// Row driver on a Schnakenberg row with per-cell parameters and sources: in place (out == u)
// equals out of place, field parameters equal scalar parameters when the rows are constant,
// nullptr sources equal zero rows, the floor clamps, and *worst holds the maxima.
TEST(ReactionKernelRow, InPlaceFieldParamsSourcesAndFloor) {
  using M = mm::Schnakenberg;
  const auto p = defaults<M>();
  const int n = 16;
  std::vector<double> u0(n), u1(n), s0a(n), s0b(n), s1a(n), s1b(n), zero(n, 0.0);
  std::vector<std::vector<double>> prow(M::nparams, std::vector<double>(n));
  for (int i = 0; i < n; ++i) {
    u0[i] = 0.2 + 0.15 * i;
    u1[i] = 1.5 - 0.08 * i;
    s0a[i] = 0.01 * std::sin(i);
    s0b[i] = 0.02 * std::cos(i);
    s1a[i] = -0.5 * s0a[i];
    s1b[i] = 0.3 * s0b[i];
    for (int q = 0; q < M::nparams; ++q)
      prow[q][i] = p[q];
  }
  const double* S0[2] = {s0a.data(), s0b.data()};
  const double* S1[2] = {s1a.data(), s1b.data()};
  const double* Z[2] = {zero.data(), zero.data()};
  const double* P[M::nparams] = {prow[0].data(), prow[1].data(), prow[2].data()};
  const double noclamp[2] = {-HUGE_VAL, -HUGE_VAL};
  const double dt = 0.2, tol = 1e-12;
  for (ReactionScheme scheme : kAllSchemes) {
    SCOPED_TRACE(scheme_name(scheme));
    const double* in[2] = {u0.data(), u1.data()};
    // Out of place, scalar parameters: the reference, checked cell by cell.
    std::vector<double> ra(n), rb(n);
    double* ref[2] = {ra.data(), rb.data()};
    CellSolve worst{};
    ASSERT_EQ((reaction_row<M, false>(scheme, n, in, nullptr, p.data(), S0, S1, dt, tol, 20,
                                      noclamp, ref, &worst)),
              -1);
    EXPECT_TRUE(worst.converged);
    int maxit = 0;
    double maxres = 0.0;
    for (int i = 0; i < n; ++i) {
      const double u[2] = {u0[i], u1[i]}, a[2] = {s0a[i], s0b[i]}, b[2] = {s1a[i], s1b[i]};
      double v[2];
      const CellSolve cs = reaction_cell<M>(scheme, u, p.data(), a, b, dt, tol, 20, v);
      EXPECT_EQ(v[0], ra[i]);
      EXPECT_EQ(v[1], rb[i]);
      maxit = std::max(maxit, cs.iterations);
      maxres = std::max(maxres, cs.residual);
    }
    EXPECT_EQ(worst.iterations, maxit);
    EXPECT_EQ(worst.residual, maxres);
    // In place with field parameters.
    std::vector<double> ia(u0), ib(u1);
    double* io[2] = {ia.data(), ib.data()};
    ASSERT_EQ((reaction_row<M, true>(scheme, n, io, P, nullptr, S0, S1, dt, tol, 20, noclamp, io,
                                     &worst)),
              -1);
    for (int i = 0; i < n; ++i) {
      EXPECT_EQ(ia[i], ra[i]);
      EXPECT_EQ(ib[i], rb[i]);
    }
    // nullptr sources equal zero rows; worst may be nullptr.
    std::vector<double> za(n), zb(n), na(n), nb(n);
    double* zo[2] = {za.data(), zb.data()};
    double* no[2] = {na.data(), nb.data()};
    ASSERT_EQ((reaction_row<M, false>(scheme, n, in, nullptr, p.data(), Z, Z, dt, tol, 20, noclamp,
                                      zo, nullptr)),
              -1);
    ASSERT_EQ((reaction_row<M, false>(scheme, n, in, nullptr, p.data(), nullptr, nullptr, dt, tol,
                                      20, noclamp, no, nullptr)),
              -1);
    EXPECT_EQ(za, na);
    EXPECT_EQ(zb, nb);
    // The floor clamps after the solve: a floor above every result pins every cell to it.
    const double high[2] = {100.0, -HUGE_VAL};
    ASSERT_EQ((reaction_row<M, false>(scheme, n, in, nullptr, p.data(), S0, S1, dt, tol, 20, high,
                                      zo, nullptr)),
              -1);
    for (int i = 0; i < n; ++i) {
      EXPECT_EQ(za[i], 100.0);
      EXPECT_EQ(zb[i], rb[i]);
    }
  }
}

} // namespace
