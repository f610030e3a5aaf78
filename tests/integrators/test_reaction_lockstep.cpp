// The lockstep Newton row solver (integrators/reaction_lockstep_kernel.hpp) against the
// per-cell solver it replaces for compiled models (reaction_row, reaction_kernel.hpp), for every
// compiled model, BackwardEuler and Trapezoidal, scalar and per-cell parameters, with and without
// sources, at dt = 0.1, 1 and 10 / ||J||_inf (the last needs damping in some cells), on rows of
// 37 cells (not a multiple of the lanes; the agreement test also 2 full chunks of
// kLockstepLanes and 23 cells) spread +-30 % around the steady state:
//   - both return the same status; every cell agrees to 4 tol (1 + |v|): each solver stops
//     when Newton's update is below tol (1 + ...), so two correct iterates differ by at most
//     about twice that (they may stop one iteration apart when rounding moves a cell across the
//     threshold);
//   - the worst iteration count differs by at most 1;
//   - a NaN cell and an unsolvable cell are reported at the same index by both, with the cells
//     before it written;
//   - the explicit schemes (Euler, Heun, Rk4: the vectorised row of reaction_explicit_kernel.hpp)
//     agree with the per-cell path to an ulp and bitwise with themselves on a shifted row.
#include "../model_typed_tests.hpp"
#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "integrators/reaction_lockstep_kernel.hpp"
#include "models/all_models.hpp"

namespace {

using namespace morphogen;

MG_MODEL_TYPED_TEST_SUITE(LockstepModels);

// A row of n cells around the steady state (or the species' initial values), parameters per
// cell within +-5 % of their defaults, sources of a few per cent of the state per unit time.
template <class M> struct Row {
  static constexpr int NS = M::nspecies, NP = M::nparams;
  int n;
  std::vector<std::vector<double>> u, s0, s1, p;
  std::array<double, NP> pdef{};
  double jnorm = 0.0;
  explicit Row(int n_) : n(n_), u(NS), s0(NS), s1(NS), p(NP) {
    for (int q = 0; q < NP; ++q)
      pdef[q] = M::params[q].def;
    double us[NS];
    if (!M::steady_state(pdef.data(), us))
      for (int s = 0; s < NS; ++s)
        us[s] = M::species[s].init;
    for (int s = 0; s < NS; ++s)
      for (int i = 0; i < n; ++i) {
        u[s].push_back(us[s] * (1.0 + 0.3 * std::sin(1.7 * i + s)) + 0.01 * (i % 3));
        s0[s].push_back(0.02 * (std::fabs(us[s]) + 0.01) * std::cos(i + 2.0 * s));
        s1[s].push_back(-0.5 * s0[s].back());
      }
    for (int q = 0; q < NP; ++q)
      for (int i = 0; i < n; ++i)
        p[q].push_back(pdef[q] * (1.0 + 0.05 * std::sin(0.3 * i + q)));
    double J[NS * NS];
    M::jacobian(us, pdef.data(), J);
    for (int r = 0; r < NS; ++r) {
      double row = 0.0;
      for (int c = 0; c < NS; ++c)
        row += std::fabs(J[r * NS + c]);
      jnorm = std::max(jnorm, row);
    }
  }
  template <class V> static std::vector<const double*> ptrs(const V& rows) {
    std::vector<const double*> out;
    for (const auto& r : rows)
      out.push_back(r.data());
    return out;
  }
};

// Runs both solvers on the row; returns {status generic, status lockstep}.
template <class M>
std::pair<int, int> compare(const Row<M>& row, ReactionScheme scheme, bool field, bool sources,
                            double dt, double tol) {
  constexpr int NS = M::nspecies;
  const int n = row.n;
  std::vector<std::vector<double>> a(NS, std::vector<double>(n, -7.0)), b = a;
  std::vector<double*> pa, pb;
  for (int s = 0; s < NS; ++s) {
    pa.push_back(a[s].data());
    pb.push_back(b[s].data());
  }
  const auto u = Row<M>::ptrs(row.u), s0 = Row<M>::ptrs(row.s0), s1 = Row<M>::ptrs(row.s1),
             p = Row<M>::ptrs(row.p);
  const std::vector<double> floor(NS, -HUGE_VAL);
  const double* const* S0 = sources ? s0.data() : nullptr;
  const double* const* S1 = sources ? s1.data() : nullptr;
  CellSolve wg{}, wl{};
  int rg, rl;
  if (field) {
    rg = reaction_row<M, true>(scheme, n, u.data(), p.data(), nullptr, S0, S1, dt, tol, 20,
                               floor.data(), pa.data(), &wg);
    rl = reaction_row_lockstep<M, true>(scheme, n, u.data(), p.data(), nullptr, S0, S1, dt, tol, 20,
                                        floor.data(), pb.data(), &wl);
  } else {
    rg = reaction_row<M, false>(scheme, n, u.data(), nullptr, row.pdef.data(), S0, S1, dt, tol, 20,
                                floor.data(), pa.data(), &wg);
    rl = reaction_row_lockstep<M, false>(scheme, n, u.data(), nullptr, row.pdef.data(), S0, S1, dt,
                                         tol, 20, floor.data(), pb.data(), &wl);
  }
  const int written = rg < 0 ? n : rg;
  for (int s = 0; s < NS; ++s)
    for (int i = 0; i < written; ++i)
      EXPECT_NEAR(a[s][i], b[s][i], 4.0 * tol * (1.0 + std::fabs(a[s][i])))
          << "species " << s << " cell " << i;
  if (rg < 0 && rl < 0) {
    EXPECT_LE(std::abs(wg.iterations - wl.iterations), 1);
    EXPECT_TRUE(wl.converged);
  }
  return {rg, rl};
}

TYPED_TEST(LockstepModels, AgreesWithThePerCellSolver) {
  using M = TypeParam;
  Row<M> row(2 * detail::kLockstepLanes + 23); // full chunks and a partial one
  ASSERT_GT(row.jnorm, 0.0);
  for (ReactionScheme scheme : {ReactionScheme::BackwardEuler, ReactionScheme::Trapezoidal})
    for (bool field : {false, true})
      for (bool sources : {false, true})
        for (double f : {0.1, 1.0, 10.0}) {
          SCOPED_TRACE(std::string(scheme == ReactionScheme::Trapezoidal ? "TR" : "BE") +
                       (field ? " field" : " scalar") + (sources ? " sources" : "") +
                       " dt*|J| = " + std::to_string(f));
          const auto [rg, rl] = compare<M>(row, scheme, field, sources, f / row.jnorm, 1e-12);
          EXPECT_EQ(rg, rl);
        }
}

TYPED_TEST(LockstepModels, ReportsTheSameFailedCell) {
  using M = TypeParam;
  Row<M> row(37);
  row.u[0][19] = std::nan("");
  const auto [rg, rl] =
      compare<M>(row, ReactionScheme::Trapezoidal, false, false, 0.5 / row.jnorm, 1e-12);
  EXPECT_EQ(rg, 19);
  EXPECT_EQ(rl, 19);
  // maxit 1 at a large step: the per-cell solver's verdict (fails somewhere, or not) is kept.
  Row<M> far(37);
  constexpr int NS = M::nspecies;
  std::vector<std::vector<double>> a(NS, std::vector<double>(37)), b = a;
  std::vector<double*> pa, pb;
  for (int s = 0; s < NS; ++s) {
    pa.push_back(a[s].data());
    pb.push_back(b[s].data());
  }
  const auto u = Row<M>::ptrs(far.u);
  const std::vector<double> floor(NS, -HUGE_VAL);
  CellSolve wg{}, wl{};
  const double dt = 30.0 / far.jnorm;
  const int rg1 =
      reaction_row<M, false>(ReactionScheme::BackwardEuler, 37, u.data(), nullptr, far.pdef.data(),
                             nullptr, nullptr, dt, 1e-12, 1, floor.data(), pa.data(), &wg);
  const int rl1 = reaction_row_lockstep<M, false>(ReactionScheme::BackwardEuler, 37, u.data(),
                                                  nullptr, far.pdef.data(), nullptr, nullptr, dt,
                                                  1e-12, 1, floor.data(), pb.data(), &wl);
  EXPECT_EQ(rg1, rl1);
  if (rg1 >= 0) {
    EXPECT_EQ(wg.iterations, wl.iterations);
  }
}

// Euler, Heun and Rk4 rows (reaction_explicit_kernel.hpp, reached through reaction_row_lockstep)
// against the per-cell path: equal to an ulp, in place too (out aliasing u), and bitwise
// independent of a cell's place in the row; a NaN cell is reported at its index with the cells
// before it written and those from it on untouched.
TYPED_TEST(LockstepModels, ExplicitRowsAreBitwiseThePerCellPath) {
  using M = TypeParam;
  constexpr int NS = M::nspecies;
  Row<M> row(37);
  const std::vector<double> floor(NS, -HUGE_VAL);
  const auto u = Row<M>::ptrs(row.u), s0 = Row<M>::ptrs(row.s0), s1 = Row<M>::ptrs(row.s1),
             p = Row<M>::ptrs(row.p);
  for (ReactionScheme scheme : {ReactionScheme::Euler, ReactionScheme::Heun, ReactionScheme::Rk4})
    for (bool field : {false, true})
      for (bool sources : {false, true}) {
        SCOPED_TRACE(std::string(scheme == ReactionScheme::Heun  ? "Heun"
                                 : scheme == ReactionScheme::Rk4 ? "Rk4"
                                                                 : "Euler") +
                     (field ? " field" : " scalar") + (sources ? " sources" : ""));
        const double* const* S0 = sources ? s0.data() : nullptr;
        const double* const* S1 = sources ? s1.data() : nullptr;
        const double* const* prow = field ? p.data() : nullptr;
        const double* pconst = field ? nullptr : row.pdef.data();
        std::vector<std::vector<double>> a(NS, std::vector<double>(37)), b = row.u;
        std::vector<double*> pa, pb;
        for (int s = 0; s < NS; ++s) {
          pa.push_back(a[s].data());
          pb.push_back(b[s].data());
        }
        const double dt = 0.3 / row.jnorm;
        CellSolve wg{}, wl{};
        const int rg = field ? reaction_row<M, true>(scheme, 37, u.data(), prow, pconst, S0, S1, dt,
                                                     1e-12, 20, floor.data(), pa.data(), &wg)
                             : reaction_row<M, false>(scheme, 37, u.data(), prow, pconst, S0, S1,
                                                      dt, 1e-12, 20, floor.data(), pa.data(), &wg);
        const std::vector<const double*> in(pb.begin(), pb.end()); // in place: out aliases u
        const int rl =
            field ? reaction_row_lockstep<M, true>(scheme, 37, in.data(), prow, pconst, S0, S1, dt,
                                                   1e-12, 20, floor.data(), pb.data(), &wl)
                  : reaction_row_lockstep<M, false>(scheme, 37, in.data(), prow, pconst, S0, S1, dt,
                                                    1e-12, 20, floor.data(), pb.data(), &wl);
        EXPECT_EQ(rg, -1);
        EXPECT_EQ(rl, -1);
        EXPECT_TRUE(wl.converged);
        EXPECT_EQ(wl.iterations, 0);
        for (int s = 0; s < NS; ++s)
          for (int i = 0; i < 37; ++i) // an ulp: a multiply-add may be contracted differently
            ASSERT_NEAR(a[s][i], b[s][i],
                        4.0 * DBL_EPSILON * (std::fabs(a[s][i]) + std::fabs(row.u[s][i])))
                << "species " << s << " cell " << i;
        // The same cells as a row starting 5 cells later: bitwise the same values.
        std::vector<std::vector<double>> c(NS, std::vector<double>(32));
        std::vector<const double*> in5, p5, a5, b5;
        std::vector<double*> pc;
        for (int s = 0; s < NS; ++s) {
          in5.push_back(row.u[s].data() + 5);
          a5.push_back(row.s0[s].data() + 5);
          b5.push_back(row.s1[s].data() + 5);
          pc.push_back(c[s].data());
        }
        for (int q = 0; q < M::nparams; ++q)
          p5.push_back(row.p[q].data() + 5);
        const int r5 =
            field ? reaction_row_lockstep<M, true>(
                        scheme, 32, in5.data(), p5.data(), nullptr, sources ? a5.data() : nullptr,
                        sources ? b5.data() : nullptr, dt, 1e-12, 20, floor.data(), pc.data(), &wl)
                  : reaction_row_lockstep<M, false>(
                        scheme, 32, in5.data(), nullptr, pconst, sources ? a5.data() : nullptr,
                        sources ? b5.data() : nullptr, dt, 1e-12, 20, floor.data(), pc.data(), &wl);
        EXPECT_EQ(r5, -1);
        for (int s = 0; s < NS; ++s)
          for (int i = 0; i < 32; ++i)
            ASSERT_EQ(c[s][i], b[s][i + 5]) << "species " << s << " cell " << i + 5;
      }
  row.u[NS - 1][21] = std::nan("");
  std::vector<std::vector<double>> b(NS, std::vector<double>(37, -7.0));
  std::vector<double*> pb;
  for (int s = 0; s < NS; ++s)
    pb.push_back(b[s].data());
  const auto un = Row<M>::ptrs(row.u);
  CellSolve wl{};
  const int rl = reaction_row_lockstep<M, false>(ReactionScheme::Heun, 37, un.data(), nullptr,
                                                 row.pdef.data(), nullptr, nullptr, 0.3 / row.jnorm,
                                                 1e-12, 20, floor.data(), pb.data(), &wl);
  EXPECT_EQ(rl, 21);
  EXPECT_FALSE(wl.converged);
  for (int s = 0; s < NS; ++s) {
    EXPECT_NE(b[s][20], -7.0);
    EXPECT_EQ(b[s][21], -7.0);
    EXPECT_EQ(b[s][36], -7.0);
  }
}

// The 3x3 Cramer solve against a hand-checked system, and its singularity test.
// In place (out aliases u), a non-finite cell in a full 16-cell chunk and in the row's last
// partial chunk: the index is reported, the cells before it hold the values of a run without it
// (out apart), it and the cells after it keep their inputs.
TYPED_TEST(LockstepModels, ExplicitRowInPlaceStopsAtTheFirstNonFiniteCell) {
  using M = TypeParam;
  constexpr int NS = M::nspecies;
  const int n = 40; // two full chunks and 8 cells
  const std::vector<double> floor(NS, -HUGE_VAL);
  for (int at : {21, 36})
    for (ReactionScheme scheme :
         {ReactionScheme::Euler, ReactionScheme::Heun, ReactionScheme::Rk4}) {
      SCOPED_TRACE("non-finite cell " + std::to_string(at));
      Row<M> row(n);
      const double dt = 0.3 / row.jnorm;
      std::vector<std::vector<double>> ref(NS, std::vector<double>(n));
      std::vector<double*> pr;
      for (int s = 0; s < NS; ++s)
        pr.push_back(ref[s].data());
      CellSolve w{};
      const auto u0 = Row<M>::ptrs(row.u);
      const int r0 =
          reaction_row_lockstep<M, false>(scheme, n, u0.data(), nullptr, row.pdef.data(), nullptr,
                                          nullptr, dt, 1e-12, 20, floor.data(), pr.data(), &w);
      ASSERT_EQ(r0, -1);
      auto v = row.u;
      v[0][static_cast<size_t>(at)] = std::nan("");
      const auto before = v;
      std::vector<double*> pv;
      for (int s = 0; s < NS; ++s)
        pv.push_back(v[s].data());
      const std::vector<const double*> in(pv.begin(), pv.end());
      const int r1 =
          reaction_row_lockstep<M, false>(scheme, n, in.data(), nullptr, row.pdef.data(), nullptr,
                                          nullptr, dt, 1e-12, 20, floor.data(), pv.data(), &w);
      EXPECT_EQ(r1, at);
      for (int s = 0; s < NS; ++s)
        for (int i = 0; i < n; ++i) {
          const double want = i < at ? ref[s][i] : before[s][i];
          if (std::isnan(want))
            EXPECT_TRUE(std::isnan(v[s][i])) << "species " << s << " cell " << i;
          else
            EXPECT_EQ(v[s][i], want) << "species " << s << " cell " << i;
        }
    }
}

TEST(LockstepCramer, SolvesAndDetectsSingular) {
  const double A[9] = {4, 1, 0, 1, 3, 1, 0, 1, 2}, b[3] = {1, 2, 3};
  double x[3];
  ASSERT_TRUE(detail::cramer_solve<3>(A, b, x));
  for (int r = 0; r < 3; ++r)
    EXPECT_NEAR(A[3 * r] * x[0] + A[3 * r + 1] * x[1] + A[3 * r + 2] * x[2], b[r], 1e-14);
  const double S[9] = {1, 2, 3, 2, 4, 6, 0, 1, 1};
  EXPECT_FALSE(detail::cramer_solve<3>(S, b, x));
  const double A2[4] = {2, 1, 1, 3}, b2[2] = {3, 5};
  double x2[2];
  ASSERT_TRUE(detail::cramer_solve<2>(A2, b2, x2));
  EXPECT_NEAR(x2[0], 0.8, 1e-15);
  EXPECT_NEAR(x2[1], 1.4, 1e-15);
  const double S2[4] = {1, 2, 2, 4};
  EXPECT_FALSE(detail::cramer_solve<2>(S2, b2, x2));
}

} // namespace
