// Unit tests of the reaction models (serial, header-only code; no MPI or PETSc).
//
// Every model in AllModels is checked for
//   1. rates at one state against hand-computed values (literals below, with the arithmetic),
//   2. the analytic Jacobian against central finite differences at three states,
//   3. a zero residual at the steady state, and that the default initial values are that state,
//   4. consistent metadata (ranges contain the defaults, unique identifier-like names),
//   5. linear stability of the steady state with the default parameters and diffusion; for
//      the Turing-type models: stable without diffusion, unstable to some wavenumber k.
#include "../model_typed_tests.hpp"
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "models/all_models.hpp"

namespace {

using namespace morphogen;
namespace mm = morphogen::models;

// Linear stability of the default steady state to modes exp(i k x) with the default D.
enum class TuringKind {
  unstable,    // Turing-type: stable at k = 0, some k > 0 grows
  marginal,    // Turing-type at its critical point: stable at k = 0, fastest k has zero growth
  stable,      // stable at every k (Gray-Scott, excitable rest states): needs a finite seed
  unstable_k0, // unstable without diffusion (oscillatory or bistable medium)
};

// Per-model test data: a state u with the hand-computed rates r at the default parameters,
// three states for the Jacobian check, and the linear stability expected.
template <class M> struct Case;

template <> struct Case<mm::Turing> {
  // alpha = 12, beta = 16, s = 1/128, (a, b) = (2, 3):
  //   R_a = (2*3 - 2 - 12) / 128 = -8/128,  R_b = (16 - 2*3) / 128 = 10/128
  static constexpr std::array<double, 2> u{2.0, 3.0};
  static constexpr std::array<double, 2> r{-0.0625, 0.078125};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{4.0, 4.0}, {1.0, 6.0}, {7.5, 0.3}}};
  // Turk's parameters sit exactly on the Turing bifurcation (d_b J_aa + d_a J_bb equals
  // 2 sqrt(d_a d_b det J)); the pattern in the paper is driven by the +-0.1% parameter noise.
  static constexpr TuringKind turing = TuringKind::marginal;
};

template <> struct Case<mm::GrayScott> {
  // F = 0.04, k = 0.06, s = 1, (a, b) = (0.5, 0.25): a^2 b = 0.0625
  //   R_a = 0.0625 - 0.1*0.5 = 0.0125,  R_b = -0.0625 + 0.04*0.75 = -0.0325
  static constexpr std::array<double, 2> u{0.5, 0.25};
  static constexpr std::array<double, 2> r{0.0125, -0.0325};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{0.25, 0.5}, {0.1, 0.9}, {0.4, 0.2}}};
  static constexpr TuringKind turing = TuringKind::stable;
};

template <> struct Case<mm::GrayScottSims> {
  // f = 0.055, k = 0.062, (A, B) = (0.5, 0.25): A B^2 = 0.03125
  //   R_A = -0.03125 + 0.055*0.5 = -0.00375,  R_B = 0.03125 - 0.117*0.25 = 0.002
  static constexpr std::array<double, 2> u{0.5, 0.25};
  static constexpr std::array<double, 2> r{-0.00375, 0.002};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{1.0, 0.0}, {0.3, 0.4}, {0.6, 0.2}}};
  static constexpr TuringKind turing = TuringKind::stable;
};

template <> struct Case<mm::Brusselator> {
  // alpha = 3, beta = 9, s = 1, (a, b) = (2, 1): a^2 b = 4
  //   R_a = 3 - 10*2 + 4 = -13,  R_b = 9*2 - 4 = 14
  static constexpr std::array<double, 2> u{2.0, 1.0};
  static constexpr std::array<double, 2> r{-13.0, 14.0};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{3.0, 3.0}, {1.0, 5.0}, {4.5, 0.5}}};
  static constexpr TuringKind turing = TuringKind::unstable;
};

template <> struct Case<mm::GiererMeinhardt> {
  // alpha = 1, beta = 1.5, gamma = 0.1, s = 0.5, (a, b) = (2, 4):
  //   R_a = 0.5 (0.1 + 4/4 - 2) = -0.45,  R_b = 0.5 (4 - 1.5*4) = -1
  static constexpr std::array<double, 2> u{2.0, 4.0};
  static constexpr std::array<double, 2> r{-0.45, -1.0};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{1.6, 1.7}, {0.5, 2.0}, {3.0, 0.8}}};
  static constexpr TuringKind turing = TuringKind::unstable;
};

template <> struct Case<mm::Meinhardt> {
  // s = 1, alpha = 100 (0.01 alpha = 1), p1 = -1, p2 = -1.5, p3 = 0.05, (A, B) = (2, 4):
  //   R_A = -2 + 4/4 + 0.05 = -0.95,  R_B = -1.5*4 + 4 = -2
  static constexpr std::array<double, 2> u{2.0, 4.0};
  static constexpr std::array<double, 2> r{-0.95, -2.0};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{1.55, 1.6}, {0.5, 2.0}, {3.0, 0.8}}};
  static constexpr TuringKind turing = TuringKind::unstable;
};

template <> struct Case<mm::Schnakenberg> {
  // a = 0.1, b = 0.9, gamma = 1, (u, v) = (2, 0.5): u^2 v = 2
  //   R_u = 0.1 - 2 + 2 = 0.1,  R_v = 0.9 - 2 = -1.1
  static constexpr std::array<double, 2> u{2.0, 0.5};
  static constexpr std::array<double, 2> r{0.1, -1.1};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{1.0, 0.9}, {0.3, 2.0}, {2.5, 0.1}}};
  static constexpr TuringKind turing = TuringKind::unstable;
};

template <> struct Case<mm::FitzHughNagumo> {
  // eps = 0.1, a0 = 0, a1 = 2, (A, B) = (0.5, 0.1):
  //   R_A = 0.5 - 0.125 - 0.1 = 0.275,  R_B = 0.1 (0.5 - 2*0.1 - 0) = 0.03
  static constexpr std::array<double, 2> u{0.5, 0.1};
  static constexpr std::array<double, 2> r{0.275, 0.03};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{0.0, 0.0}, {0.7, -0.3}, {-1.1, 0.4}}};
  static constexpr TuringKind turing = TuringKind::unstable_k0;
};

template <> struct Case<mm::Barkley> {
  // a = 0.75, b = 0.02, eps = 0.02, (A, B) = (0.5, 0.25): threshold (0.25 + 0.02)/0.75 = 0.36
  //   R_A = 0.5*0.5*(0.5 - 0.36)/0.02 = 1.75,  R_B = 0.5 - 0.25 = 0.25
  static constexpr std::array<double, 2> u{0.5, 0.25};
  static constexpr std::array<double, 2> r{1.75, 0.25};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{0.0, 0.0}, {0.5, 0.2}, {0.95, 0.6}}};
  static constexpr TuringKind turing = TuringKind::stable;
};

template <> struct Case<mm::BarkleyTurbulent> {
  // a = 0.75, b = 0.06, eps = 0.08, (A, B) = (0.5, 0.25): threshold 0.31/0.75 = 31/75
  //   R_A = 0.25 (0.5 - 31/75) / 0.08 = 0.25 (6.5/75) / 0.08 = 13/48,  R_B = 0.125 - 0.25
  static constexpr std::array<double, 2> u{0.5, 0.25};
  static constexpr std::array<double, 2> r{13.0 / 48.0, -0.125};
  static constexpr std::array<std::array<double, 2>, 3> jac{{{0.0, 0.0}, {0.5, 0.2}, {0.95, 0.6}}};
  static constexpr TuringKind turing = TuringKind::stable;
};

template <> struct Case<mm::Oregonator> {
  // eps = 0.02, f = 1.4, q = 0.002, (a, b) = (0.1, 0.2): (a - q)/(a + q) = 0.098/0.102 = 49/51
  //   R_a = 50 (0.1 - 0.01 - 1.4*0.2*49/51) = 4.5 - 686/51 = -913/102,  R_b = 0.1 - 0.2
  static constexpr std::array<double, 2> u{0.1, 0.2};
  static constexpr std::array<double, 2> r{-913.0 / 102.0, -0.1};
  static constexpr std::array<std::array<double, 2>, 3> jac{
      {{0.0116, 0.0116}, {0.1, 0.2}, {0.8, 0.05}}};
  static constexpr TuringKind turing = TuringKind::unstable_k0;
};

template <class M> std::array<double, M::nparams> defaults() {
  std::array<double, M::nparams> p{};
  for (int i = 0; i < M::nparams; ++i)
    p[i] = M::params[i].def;
  return p;
}

bool is_identifier(const char* s) {
  if (s == nullptr || *s == '\0') return false;
  if (!(std::isalpha(static_cast<unsigned char>(*s)) || *s == '_')) return false;
  for (; *s; ++s)
    if (!(std::isalnum(static_cast<unsigned char>(*s)) || *s == '_')) return false;
  return true;
}

MG_MODEL_TYPED_TEST_SUITE(ModelTest);

TYPED_TEST(ModelTest, RatesMatchHandComputedValues) {
  using M = TypeParam;
  using C = Case<M>;
  static_assert(M::nspecies == static_cast<int>(C::u.size()));
  const auto p = defaults<M>();
  std::array<double, M::nspecies> r{};
  M::rates(C::u.data(), p.data(), r.data());
  for (int s = 0; s < M::nspecies; ++s)
    EXPECT_NEAR(r[s], C::r[s], 1e-12 * std::fabs(C::r[s])) << "species " << M::species[s].name;
}

TYPED_TEST(ModelTest, JacobianMatchesFiniteDifferences) {
  using M = TypeParam;
  constexpr int N = M::nspecies;
  const auto p = defaults<M>();
  for (const auto& u0 : Case<M>::jac) {
    std::array<double, N * N> J{};
    M::jacobian(u0.data(), p.data(), J.data());
    double scale = 0.0;
    for (double x : J)
      scale = std::max(scale, std::fabs(x));
    for (int q = 0; q < N; ++q) {
      const double h = 1e-6 * (1.0 + std::fabs(u0[q]));
      std::array<double, N> up = u0, um = u0, rp{}, rm{};
      up[q] += h;
      um[q] -= h;
      M::rates(up.data(), p.data(), rp.data());
      M::rates(um.data(), p.data(), rm.data());
      for (int s = 0; s < N; ++s) {
        const double fd = (rp[s] - rm[s]) / (2.0 * h);
        EXPECT_NEAR(J[s * N + q], fd, 1e-6 * std::max(scale, 1e-300))
            << "dR_" << M::species[s].name << "/d" << M::species[q].name << " at (" << u0[0] << ", "
            << u0[1] << ")";
      }
    }
  }
}

TYPED_TEST(ModelTest, SteadyStateHasZeroResidualAndIsTheDefaultStart) {
  using M = TypeParam;
  constexpr int N = M::nspecies;
  const auto p = defaults<M>();
  std::array<double, N> u{}, r{};
  ASSERT_TRUE(M::steady_state(p.data(), u.data()));
  M::rates(u.data(), p.data(), r.data());
  for (int s = 0; s < N; ++s) {
    EXPECT_LT(std::fabs(r[s]), 1e-10) << "species " << M::species[s].name;
    EXPECT_NEAR(M::species[s].init, u[s], 1e-12 * std::max(1.0, std::fabs(u[s])))
        << "species " << M::species[s].name;
  }
}

TYPED_TEST(ModelTest, MetadataIsConsistent) {
  using M = TypeParam;
  static_assert(static_cast<int>(M::species.size()) == M::nspecies);
  static_assert(static_cast<int>(M::params.size()) == M::nparams);
  EXPECT_TRUE(is_identifier(M::name));
  EXPECT_STRNE(M::doc, "");
  EXPECT_STRNE(M::reference, "");
  std::set<std::string> names;
  for (const auto& sp : M::species) {
    EXPECT_TRUE(is_identifier(sp.name)) << sp.name;
    EXPECT_TRUE(names.insert(sp.name).second) << "duplicate species " << sp.name;
    EXPECT_GE(sp.D, 0.0) << sp.name;
    EXPECT_STRNE(sp.doc, "");
  }
  names.clear();
  for (const auto& pi : M::params) {
    EXPECT_TRUE(is_identifier(pi.name)) << pi.name;
    EXPECT_TRUE(names.insert(pi.name).second) << "duplicate parameter " << pi.name;
    EXPECT_LE(pi.lo, pi.def) << pi.name;
    EXPECT_LE(pi.def, pi.hi) << pi.name;
    EXPECT_STRNE(pi.doc, "");
  }
}

// Largest real part of the eigenvalues of the 2x2 matrix J - k^2 diag(D).
double growth_rate(const std::array<double, 4>& J, const std::array<double, 2>& D, double k) {
  const double a = J[0] - k * k * D[0], d = J[3] - k * k * D[1];
  const double tr = a + d, det = a * d - J[1] * J[2];
  const double disc = 0.25 * tr * tr - det;
  return 0.5 * tr + (disc > 0.0 ? std::sqrt(disc) : 0.0);
}

// Largest growth rate over k in [0, pi] (pi: the Nyquist limit of a unit-spacing grid), by a
// coarse scan and golden-section refinement around the best sample. Returns {k, rate}.
std::array<double, 2> fastest_mode(const std::array<double, 4>& J, const std::array<double, 2>& D) {
  const double kmax = std::numbers::pi;
  const int n = 20000;
  double kb = 0.0, gb = growth_rate(J, D, 0.0);
  for (int i = 1; i <= n; ++i) {
    const double k = kmax * i / n, g = growth_rate(J, D, k);
    if (g > gb) gb = g, kb = k;
  }
  double lo = std::max(0.0, kb - kmax / n), hi = std::min(kmax, kb + kmax / n);
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 100; ++it) {
    const double k1 = hi - phi * (hi - lo), k2 = lo + phi * (hi - lo);
    if (growth_rate(J, D, k1) < growth_rate(J, D, k2))
      lo = k1;
    else
      hi = k2;
  }
  kb = 0.5 * (lo + hi);
  return {kb, growth_rate(J, D, kb)};
}

TYPED_TEST(ModelTest, LinearStabilityOfTheSteadyState) {
  using M = TypeParam;
  constexpr TuringKind kind = Case<M>::turing;
  static_assert(M::nspecies == 2);
  const auto p = defaults<M>();
  std::array<double, 2> u{};
  ASSERT_TRUE(M::steady_state(p.data(), u.data()));
  std::array<double, 4> J{};
  M::jacobian(u.data(), p.data(), J.data());
  const std::array<double, 2> D{M::species[0].D, M::species[1].D};
  const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2];
  double scale = 0.0;
  for (double x : J)
    scale = std::max(scale, std::fabs(x));
  const auto [kb, gb] = fastest_mode(J, D);

  if constexpr (kind == TuringKind::unstable_k0) {
    EXPECT_GT(growth_rate(J, D, 0.0), 0.0) << "tr " << tr << ", det " << det;
  } else {
    // Stable without diffusion: trace < 0 and det > 0 (both eigenvalues in the left half-plane).
    EXPECT_LT(tr, 0.0);
    EXPECT_GT(det, 0.0);
    EXPECT_LT(growth_rate(J, D, 0.0), 0.0);
    if constexpr (kind == TuringKind::stable) {
      EXPECT_LT(gb, 0.0) << "mode k = " << kb << " grows";
    } else {
      std::printf("[ %s ] fastest-growing k = %.6f, wavelength 2 pi / k = %.3f grid units, "
                  "growth rate %.6g\n",
                  M::name, kb, 2.0 * std::numbers::pi / kb, gb);
      EXPECT_GT(kb, 0.0);
      EXPECT_LT(kb, std::numbers::pi) << "fastest mode not resolved on a unit-spacing grid";
      if constexpr (kind == TuringKind::unstable)
        EXPECT_GT(gb, 0.0) << "no Turing instability";
      else
        EXPECT_NEAR(gb, 0.0, 1e-9 * scale) << "expected a marginal (critical) Turing mode";
    }
  }
}

template <class... Ms> std::vector<std::string> model_names(std::tuple<Ms...>*) {
  return {Ms::name...};
}

TEST(AllModels, NamesAreUniqueAndTuringComesFirst) {
  const auto names = model_names(static_cast<AllModels*>(nullptr));
  const std::set<std::string> unique(names.begin(), names.end());
  EXPECT_EQ(unique.size(), names.size());
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), "turing");
}

// --- Steady-state branches and the cases where no steady state exists ---------------------

template <class M> double max_residual(const double* p, const double* u) {
  std::array<double, M::nspecies> r{};
  M::rates(u, p, r.data());
  double m = 0.0;
  for (double x : r)
    m = std::max(m, std::fabs(x));
  return m;
}

TEST(FitzHughNagumo, SteadyStatePicksTheUniqueOrTheMiddleRoot) {
  using M = mm::FitzHughNagumo;
  struct Want {
    double eps, a0, a1, A;
  };
  // Roots of a1 A^3 + (1 - a1) A - a0 = 0, from numpy.roots:
  const Want cases[] = {
      {0.05, -0.5, 0.5, -0.6823278038280193},   // unique: A^3 + A + 1 = 0
      {0.05, 0.3, 0.0, 0.3},                    // a1 = 0: linear
      {0.05, 0.0, 1.0, 0.0},                    // a1 = 1, a0 = 0: triple root
      {0.05, 0.125, 1.0, 0.5},                  // a1 = 1: A = cbrt(a0)
      {0.05, -0.1, 2.0, 0.10213057761649971},   // three roots -0.7526, 0.1021, 0.6505
      {0.05, 0.05, 3.0, -0.025023503666228256}, // three roots -0.8037, -0.0250, 0.8287
      {0.05, 0.5, 2.0, 0.8846461771193156},     // a1 > 1 but |a0| large: unique
  };
  for (const auto& c : cases) {
    const double p[3] = {c.eps, c.a0, c.a1};
    double u[2];
    ASSERT_TRUE(M::steady_state(p, u));
    EXPECT_NEAR(u[0], c.A, 1e-12) << "a0 = " << c.a0 << ", a1 = " << c.a1;
    EXPECT_LT(max_residual<M>(p, u), 1e-12);
  }
}

TEST(SteadyState, ReturnsFalseWhereNoneExists) {
  double u[2];
  {
    const double p[3] = {0.0, 9.0, 1.0}; // alpha = 0
    EXPECT_FALSE(mm::Brusselator::steady_state(p, u));
  }
  {
    const double p[4] = {0.0, 1.5, 0.1, 1.0}; // alpha = 0
    EXPECT_FALSE(mm::GiererMeinhardt::steady_state(p, u));
  }
  {
    const double p[5] = {1.0, 100.0, 0.0, -1.5, 0.05}; // p1 = 0
    EXPECT_FALSE(mm::Meinhardt::steady_state(p, u));
  }
  {
    const double p[5] = {1.0, 100.0, -1.0, 0.0, 0.05}; // p2 = 0
    EXPECT_FALSE(mm::Meinhardt::steady_state(p, u));
  }
  {
    const double p[5] = {1.0, 100.0, 1.0, -1.5, 0.05}; // A* = -1.55 < 0
    EXPECT_FALSE(mm::Meinhardt::steady_state(p, u));
  }
  {
    const double p[3] = {0.02, 1.4, 0.0}; // q = 0
    EXPECT_FALSE(mm::Oregonator::steady_state(p, u));
  }
  {
    const double p[3] = {0.0, 0.0, 1.0}; // a + b = 0
    EXPECT_FALSE(mm::Schnakenberg::steady_state(p, u));
  }
  {
    const double p[3] = {0.0, 0.02, 0.02}; // a = 0
    EXPECT_FALSE(mm::Barkley::steady_state(p, u));
  }
}

TEST(Oregonator, SteadyStateIsThePositiveRootOverARangeOfF) {
  using M = mm::Oregonator;
  for (double f : {0.0, 0.5, 1.0, 1.4, 2.0, 3.0, 10.0}) {
    const double p[3] = {0.02, f, 0.002};
    double u[2];
    ASSERT_TRUE(M::steady_state(p, u));
    EXPECT_GT(u[0], 0.0);
    EXPECT_EQ(u[0], u[1]);
    const double c = 1.0 - 0.002 - f;
    EXPECT_NEAR(u[0] * u[0] - c * u[0] - 0.002 * (1.0 + f), 0.0, 1e-15) << "f = " << f;
    EXPECT_LT(max_residual<M>(p, u), 1e-10) << "f = " << f;
  }
}

} // namespace
