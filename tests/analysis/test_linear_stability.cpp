// Unit tests of analysis/linear_stability against closed forms (serial, no MPI or PETSc calls).
//
// 2 x 2 reference (A(q) = J - q diag(Da, Db), s the rate scale): stable at k = 0 iff
// tr J < 0 < det J; Turing-unstable iff in addition Db J11 + Da J22 > 2 sqrt(Da Db det J),
// the critical q_c = sqrt(det J / (Da Db)), and the band edges are the roots of
// det A(q) = Da Db q^2 - (Db J11 + Da J22) q + det J = 0.
//   * Brusselator (models/brusselator.hpp: u* = (alpha, beta/alpha), J = s[[beta - 1, alpha^2],
//     [-beta, -alpha^2]]): Hopf at beta_H = 1 + alpha^2 with frequency s alpha; Turing at
//     beta_c = (1 + alpha sqrt(Da/Db))^2 with k_c^2 = s alpha / sqrt(Da Db).
//   * Gray-Scott (models/gray_scott.hpp, Pearson's form with a = v, b = u): the trivial state
//     (0, 1) has J = s diag(-(F+k), -F): always stable. Non-trivial states a+- =
//     F (1 +- sqrt(1 - 4 (F+k)^2 / F)) / (2 (F+k)), b = (F+k)/a exist iff F >= 4 (F+k)^2, i.e.
//     k <= sqrt(F)/2 - F. There J = s[[F+k, a^2], [-2(F+k), -(a^2+F)]], tr = s (k - a^2),
//     det = s^2 (F+k)(a^2 - F): a- is a saddle (a-^2 < F < a+^2 since a+ a- = F), a+ has a Hopf
//     bifurcation where a+^2 = k, which with the steady-state relations gives
//     F^2 + (2k - sqrt(k)) F + k^2 = 0, F_H(k) = (sqrt(k) - 2k - sqrt(k - 4 k^1.5)) / 2 (the
//     root with F < k, so a+^2 = k > F); a+ oscillates (Hopf) for F < F_H.
//   * Turing/Turk (models/turing.hpp) at alpha 12, beta 16, s 1/128, D (1/16, 1/4): u* = (4, 4),
//     J = s[[3, 4], [-4, -4]], exactly on the Turing threshold (Db J11 + Da J22 = 0.5 s =
//     2 sqrt(Da Db det J)), q_c = 16 s = 1/8: wavelength 2 pi sqrt(8) = 17.77 (continuous),
//     2 pi / (2 asin(sqrt(q_c)/2)) = 17.68 with the 5pt symbol along x at h = 1.
// Tolerances are stated per check; the refined k is good to ~1e-8 relative (golden section on a
// quadratic maximum), closed-form quantities to ~1e-12.
#include "analysis/linear_stability.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace morphogen;
using namespace morphogen::analysis;
using std::sqrt;
constexpr double kPi = std::numbers::pi;

const ModelEntry& model(const char* name) {
  const ModelEntry* e = find_model(name);
  EXPECT_NE(e, nullptr) << name;
  return *e;
}

double rel(double a, double b) {
  return std::abs(a - b) / std::abs(b);
}
StabilityOptions at_state(const std::vector<double>& u) {
  StabilityOptions o;
  o.u_star = u;
  return o;
}
bool starts_with(const std::string& s, const std::string& p) {
  return s.rfind(p, 0) == 0;
}
bool contains(const std::string& s, const std::string& p) {
  return s.find(p) != std::string::npos;
}

std::vector<std::complex<double>> sorted_eigs(int n, const double* A, bool general) {
  std::vector<std::complex<double>> ev(n);
  EXPECT_TRUE(eigenvalues(n, A, ev.data(), general));
  std::sort(ev.begin(), ev.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag();
  });
  return ev;
}

// ---------------------------------------------------------------------------------------------
// Eigenvalues: the general path (characteristic polynomial + Aberth) against the closed form
// and against matrices with known spectra.

TEST(Eigenvalues, GeneralPathMatchesClosedForm2x2) {
  unsigned state = 12345;
  auto rnd = [&] { // deterministic values in [-2, 2)
    state = state * 1664525u + 1013904223u;
    return 4.0 * (state >> 8) / 16777216.0 - 2.0;
  };
  for (int t = 0; t < 500; ++t) {
    const double A[4] = {rnd(), rnd(), rnd(), rnd()};
    const auto c = sorted_eigs(2, A, false), g = sorted_eigs(2, A, true);
    for (int i = 0; i < 2; ++i)
      EXPECT_LT(std::abs(c[i] - g[i]), 1e-12 * 4) << "trial " << t;
  }
}

TEST(Eigenvalues, KnownSpectrum4x4And3x3) {
  // B = blockdiag([[-1, -2], [2, -1]], 0.5, -3): eigenvalues -1 +- 2i, 0.5, -3; A = V B V^-1
  // with V = I + N (N strictly upper triangular), V^-1 = I - N + N^2 - N^3.
  const int n = 4;
  double B[16] = {-1, -2, 0, 0, 2, -1, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, -3};
  double N[16] = {0, 0.5, -1, 2, 0, 0, 1.5, 0.25, 0, 0, 0, -0.75, 0, 0, 0, 0};
  auto mul = [&](const double* X, const double* Y, double* Z) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        Z[i * n + j] = 0;
        for (int l = 0; l < n; ++l)
          Z[i * n + j] += X[i * n + l] * Y[l * n + j];
      }
  };
  double V[16], Vi[16], N2[16], N3[16], T[16], A[16];
  mul(N, N, N2);
  mul(N2, N, N3);
  for (int i = 0; i < 16; ++i) {
    const double I = (i % 5 == 0) ? 1.0 : 0.0;
    V[i] = I + N[i];
    Vi[i] = I - N[i] + N2[i] - N3[i];
  }
  mul(V, B, T);
  mul(T, Vi, A);
  const auto ev = sorted_eigs(4, A, true);
  const std::complex<double> want[4] = {-3, {-1, -2}, {-1, 2}, 0.5};
  for (int i = 0; i < 4; ++i)
    EXPECT_LT(std::abs(ev[i] - want[i]), 1e-12) << i;
  // 3 x 3: the leading block of A's similarity class, made upper block triangular.
  const double C[9] = {-1, -2, 7, 2, -1, -4, 0, 0, 0.5};
  const auto e3 = sorted_eigs(3, C, false);
  const std::complex<double> w3[3] = {{-1, -2}, {-1, 2}, 0.5};
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(std::abs(e3[i] - w3[i]), 1e-13) << i;
}

TEST(Eigenvalues, RepeatedRootsAreLessAccurate) {
  // Documented limitation of the polynomial path: a double root to ~1e-8, a triple to ~1e-5.
  const double D2[4] = {2, 1, 0, 2}, D3[9] = {2, 0, 0, 0, 2, 0, 0, 0, 2};
  for (const auto& l : sorted_eigs(2, D2, true))
    EXPECT_LT(std::abs(l - 2.0), 1e-7);
  for (const auto& l : sorted_eigs(3, D3, true))
    EXPECT_LT(std::abs(l - 2.0), 1e-4);
}

// ---------------------------------------------------------------------------------------------
// Brusselator.

TEST(Brusselator, HopfThreshold) {
  // Equal D: beta_c = (1 + alpha)^2 = 9 > beta_H = 5, so the Hopf bifurcation comes first.
  const auto& m = model("brusselator");
  const double alpha = 2, s = 1, bH = 1 + alpha * alpha;
  const auto below = analyse(m, {alpha, bH * (1 - 1e-3), s}, {1, 1});
  const auto above = analyse(m, {alpha, bH * (1 + 1e-3), s}, {1, 1});
  const auto at = analyse(m, {alpha, bH, s}, {1, 1});
  EXPECT_TRUE(below.stable_homogeneous);
  EXPECT_FALSE(below.hopf);
  EXPECT_FALSE(below.turing_unstable);
  EXPECT_TRUE(above.hopf) << summary(above);
  EXPECT_FALSE(above.turing_unstable);
  EXPECT_FALSE(above.stable_homogeneous);
  EXPECT_TRUE(starts_with(summary(above), "Hopf-unstable at k = 0")) << summary(above);
  // At beta_H: eigenvalues +- i s alpha exactly (det J = s^2 alpha^2), growth 0 (1e-12).
  EXPECT_LT(std::abs(at.growth0), 1e-12);
  EXPECT_NEAR(std::abs(at.eigen0[0].imag()), s * alpha, 1e-12);
  // Growth just above: tr/2 = s (beta - bH) / 2 (closed form, 1e-12).
  EXPECT_NEAR(above.growth0, 0.5 * s * bH * 1e-3, 1e-12);
}

TEST(Brusselator, TuringThresholdAndCriticalWavenumber) {
  // Sanderson's Table 1 layer 2: alpha 3, D 49.4 / 117.6: beta_c = 8.669 < beta_H = 10.
  const auto& m = model("brusselator");
  const double alpha = 3, s = 1, Da = 49.4, Db = 117.6;
  const double bc = std::pow(1 + alpha * sqrt(Da / Db), 2), kc = sqrt(s * alpha / sqrt(Da * Db));
  ASSERT_LT(bc, 1 + alpha * alpha);
  const auto below = analyse(m, {alpha, bc * (1 - 1e-3), s}, {Da, Db});
  const auto above = analyse(m, {alpha, bc * (1 + 1e-3), s}, {Da, Db});
  EXPECT_TRUE(below.stable_homogeneous);
  EXPECT_FALSE(below.turing_unstable);
  EXPECT_FALSE(below.marginal);
  EXPECT_LT(below.growth_fastest, 0);
  EXPECT_TRUE(above.stable_homogeneous);
  EXPECT_TRUE(above.turing_unstable) << summary(above);
  EXPECT_FALSE(above.hopf);
  EXPECT_FALSE(above.oscillatory_fastest);
  EXPECT_TRUE(above.has_band);
  EXPECT_LT(above.k_lo, kc);
  EXPECT_GT(above.k_hi, kc);
  // At beta_c: marginal, the maximum (zero growth) at k_c (1e-7 relative).
  const auto at = analyse(m, {alpha, bc, s}, {Da, Db});
  EXPECT_TRUE(at.marginal) << summary(at);
  EXPECT_LT(std::abs(at.growth_fastest), 1e-12);
  EXPECT_LT(rel(at.k_fastest, kc), 1e-7);
  // k_fastest -> k_c as beta -> beta_c from above: the error falls with the distance, and is
  // below 1e-4 relative at 1e-4 above.
  double prev = 1;
  for (double eps : {1e-1, 1e-2, 1e-3, 1e-4}) {
    const auto r = analyse(m, {alpha, bc * (1 + eps), s}, {Da, Db});
    const double err = rel(r.k_fastest, kc);
    EXPECT_LT(err, prev) << eps;
    prev = err;
  }
  EXPECT_LT(prev, 1e-4);
}

TEST(Brusselator, DefaultBandEdgesAndScaling) {
  // Default (alpha 3, beta 9, s 1): band edges are the roots of det A(q) = 0 (1e-8 relative);
  // the fastest wavelength is the README's 31.5.
  const auto& m = model("brusselator");
  const double Da = 49.4, Db = 117.6, J11 = 9 - 1, J22 = -9, det = 9;
  const double b = Db * J11 + Da * J22, disc = sqrt(b * b - 4 * Da * Db * det);
  const double q_lo = (b - disc) / (2 * Da * Db), q_hi = (b + disc) / (2 * Da * Db);
  const auto r = analyse(m, default_params(m), default_diffusion(m));
  EXPECT_TRUE(r.turing_unstable);
  EXPECT_LT(rel(r.k_lo, sqrt(q_lo)), 1e-8);
  EXPECT_LT(rel(r.k_hi, sqrt(q_hi)), 1e-8);
  EXPECT_NEAR(r.wavelength_fastest, 31.5, 0.1);
  EXPECT_TRUE(starts_with(summary(r), "Turing-unstable: fastest wavelength 31.5")) << summary(r);
  // Exact scaling with the rate s: A(q; s) = s A(q/s; 1), so k_f ~ sqrt(s), sigma_f ~ s (1e-7).
  const auto r4 = analyse(m, {3, 9, 4}, {Da, Db});
  EXPECT_LT(rel(r4.k_fastest, 2 * r.k_fastest), 1e-7);
  EXPECT_LT(rel(r4.growth_fastest, 4 * r.growth_fastest), 1e-10);
}

// ---------------------------------------------------------------------------------------------
// Gray-Scott.

struct GsStates {
  bool exist = false;
  double a_lo = 0, a_hi = 0;
};
GsStates gs_states(double F, double k) {
  const double disc = 1 - 4 * (F + k) * (F + k) / F;
  if (disc < 0) return {};
  return {true, F * (1 - sqrt(disc)) / (2 * (F + k)), F * (1 + sqrt(disc)) / (2 * (F + k))};
}
const std::vector<double> kPearsonD{1e-5, 2e-5};

TEST(GrayScott, TrivialStateAlwaysStable) {
  const auto& m = model("gray_scott");
  for (double F = 0.005; F < 0.1; F += 0.005)
    for (double k = 0.03; k < 0.075; k += 0.005) {
      const auto r = analyse(m, {F, k, 1}, kPearsonD);
      ASSERT_TRUE(r.has_steady_state);
      EXPECT_EQ(r.u_star, (std::vector<double>{0, 1}));
      EXPECT_TRUE(r.stable_homogeneous);
      EXPECT_FALSE(r.turing_unstable);
      EXPECT_NEAR(r.growth0, -F, 1e-15); // eigenvalues -(F + k), -F
      EXPECT_LE(r.growth_fastest, r.growth0 + 1e-15);
    }
}

TEST(GrayScott, NontrivialStatesExistBelowSaddleNodeCurve) {
  // On both sides of k = sqrt(F)/2 - F (at +-0.001 in k): 3 states below, only (0, 1) above;
  // the found states match the closed form (1e-8). The model's steady_state reports (0, 1).
  const auto& m = model("gray_scott");
  for (double F : {0.02, 0.04, 0.06, 0.08}) {
    const double ksn = sqrt(F) / 2 - F;
    for (double k : {ksn - 1e-3, ksn + 1e-3}) {
      const auto st = find_steady_states(m, {F, k, 1});
      const auto cf = gs_states(F, k);
      EXPECT_EQ(cf.exist, k < ksn);
      ASSERT_EQ(st.size(), cf.exist ? 3u : 1u) << "F " << F << " k " << k;
      EXPECT_NEAR(st[0][0], 0, 1e-14);
      EXPECT_NEAR(st[0][1], 1, 1e-14);
      if (cf.exist) {
        EXPECT_NEAR(st[1][0], cf.a_lo, 1e-8);
        EXPECT_NEAR(st[1][1], (F + k) / cf.a_lo, 1e-8);
        EXPECT_NEAR(st[2][0], cf.a_hi, 1e-8);
        EXPECT_NEAR(st[2][1], (F + k) / cf.a_hi, 1e-8);
        // a- is a saddle (real positive eigenvalue), whatever the diffusion.
        const auto lo = analyse(m, {F, k, 1}, kPearsonD, at_state(st[1]));
        EXPECT_GT(lo.growth0, 0);
        EXPECT_FALSE(lo.hopf);
      }
      double u[2];
      ASSERT_TRUE(m.steady_state(std::vector<double>{F, k, 1}.data(), u));
      EXPECT_EQ(u[0], 0.0);
      EXPECT_EQ(u[1], 1.0);
    }
  }
}

TEST(GrayScott, HopfCurveOfUpperState) {
  const auto& m = model("gray_scott");
  for (double k : {0.035, 0.045, 0.055, 0.06}) {
    const double FH = 0.5 * (sqrt(k) - 2 * k - sqrt(k - 4 * std::pow(k, 1.5)));
    ASSERT_TRUE(gs_states(FH, k).exist);
    // At F_H: a+^2 = k (1e-12), trace 0, frequency sqrt((F+k)(k-F)) (1e-10).
    const double ap = gs_states(FH, k).a_hi;
    EXPECT_NEAR(ap * ap, k, 1e-12);
    const auto at = analyse(m, {FH, k, 1}, kPearsonD, at_state({ap, (FH + k) / ap}));
    EXPECT_LT(std::abs(at.growth0), 1e-12);
    EXPECT_NEAR(std::abs(at.eigen0[0].imag()), sqrt((FH + k) * (k - FH)), 1e-10);
    for (double F : {FH - 1e-4, FH + 1e-4}) {
      const double a = gs_states(F, k).a_hi;
      const auto r = analyse(m, {F, k, 1}, kPearsonD, at_state({a, (F + k) / a}));
      EXPECT_EQ(r.hopf, F < FH) << "k " << k << " F " << F;
      EXPECT_NEAR(r.growth0, 0.5 * (k - a * a), 1e-12); // tr/2 (complex pair)
    }
  }
}

TEST(GrayScott, TuringClassificationMatchesClosedForm) {
  // Upper state over a grid of (F, k) with Pearson's D: turing_unstable iff tr < 0 < det and
  // Db J11 + Da J22 > 2 sqrt(Da Db det) (points within 1e-9 of a boundary skipped).
  const auto& m = model("gray_scott");
  const double Da = kPearsonD[0], Db = kPearsonD[1];
  int turing = 0, stable = 0;
  for (double F = 0.01; F < 0.1; F += 0.0025)
    for (double k = 0.03; k < 0.0625; k += 0.0005) {
      const auto cf = gs_states(F, k);
      if (!cf.exist) continue;
      const double a = cf.a_hi, tr = k - a * a, det = (F + k) * (a * a - F);
      const double margin = Db * (F + k) - Da * (a * a + F) - 2 * sqrt(Da * Db * det);
      if (std::abs(tr) < 1e-9 || std::abs(margin) < 1e-9 * Db) continue;
      const bool want = tr < 0 && det > 0 && margin > 0;
      const auto r = analyse(m, {F, k, 1}, kPearsonD, at_state({a, (F + k) / a}));
      EXPECT_EQ(r.turing_unstable, want) << "F " << F << " k " << k;
      turing += want;
      stable += tr < 0 && margin < 0;
    }
  EXPECT_GT(turing, 5);
  EXPECT_GT(stable, 100);
}

TEST(GrayScott, PearsonPoints) {
  // Pearson's (F, k) plane with D_u = 2 D_v: the upper state is Turing-unstable only in a thin
  // sliver just inside the saddle-node curve (most visibly near its nose, F = 1/16, k = 1/16);
  // most of Pearson's patterns lie where no non-trivial state exists or it is linearly stable,
  // so they need his finite square seed.
  const auto& m = model("gray_scott");
  // (0.035, 0.065), Pearson's self-replicating spots (input/gray_scott_pearson_spots.yaml):
  // above the saddle-node curve (sqrt(F)/2 - F = 0.0585), only the stable trivial state.
  {
    const auto st = find_steady_states(m, {0.035, 0.065, 1});
    ASSERT_EQ(st.size(), 1u);
    const auto r = analyse(m, {0.035, 0.065, 1}, kPearsonD);
    EXPECT_TRUE(r.stable_homogeneous);
    EXPECT_FALSE(r.turing_unstable);
  }
  // (0.06, 0.062), near the nose: upper state stable without diffusion, Turing-unstable with
  // it; fastest wavelength ~0.12 in Pearson's units (~12 cells of h = 0.01).
  {
    const double a = gs_states(0.06, 0.062).a_hi;
    const auto r = analyse(m, {0.06, 0.062, 1}, kPearsonD, at_state({a, 0.122 / a}));
    EXPECT_TRUE(r.stable_homogeneous);
    EXPECT_TRUE(r.turing_unstable) << summary(r);
    EXPECT_NEAR(r.wavelength_fastest, 0.12, 0.01);
  }
  // (0.055, 0.06), inside the curve away from it: upper state stable, no Turing instability.
  {
    const double a = gs_states(0.055, 0.06).a_hi;
    const auto r = analyse(m, {0.055, 0.06, 1}, kPearsonD, at_state({a, 0.115 / a}));
    EXPECT_TRUE(r.stable_homogeneous);
    EXPECT_FALSE(r.turing_unstable);
    EXPECT_TRUE(starts_with(summary(r), "stable")) << summary(r);
  }
  // (0.03, 0.055), left of the Hopf curve (F_H = 0.0331): the upper state oscillates.
  {
    const double a = gs_states(0.03, 0.055).a_hi;
    const auto r = analyse(m, {0.03, 0.055, 1}, kPearsonD, at_state({a, 0.085 / a}));
    EXPECT_TRUE(r.hopf);
  }
}

// ---------------------------------------------------------------------------------------------
// Turing (Turk) default deck.

TEST(TuringModel, DefaultFastestWavelengthIs17_8) {
  const auto& m = model("turing");
  const auto r = analyse(m, default_params(m), default_diffusion(m));
  EXPECT_TRUE(r.stable_homogeneous);
  EXPECT_TRUE(r.marginal) << summary(r);
  EXPECT_FALSE(r.turing_unstable);
  EXPECT_LT(std::abs(r.growth_fastest), 1e-15);
  EXPECT_LT(rel(r.wavelength_fastest, 2 * kPi * sqrt(8.0)), 1e-7);
  EXPECT_NEAR(r.wavelength_fastest, 17.8, 0.05); // the README's "17.8"
  EXPECT_TRUE(contains(summary(r), "fastest wavelength 17.8")) << summary(r);
  // The grid's 5pt symbol along x at h = 1.
  StabilityOptions o;
  o.grid = DiscreteGrid{};
  const auto g = analyse(m, default_params(m), default_diffusion(m), o);
  EXPECT_LT(rel(g.wavelength_fastest, 2 * kPi / (2 * std::asin(sqrt(0.125) / 2))), 1e-7);
  EXPECT_NEAR(g.wavelength_fastest, 17.68, 0.01);
}

TEST(TuringModel, PlusMinusPointOnePercentTipsItOver) {
  // The README: the +-0.1 % perturbation of alpha and beta tips parts of the grid over the
  // threshold: larger alpha or smaller beta is Turing-unstable, the opposite stable.
  const auto& m = model("turing");
  const double s = 1.0 / 128;
  const std::vector<double> D{1.0 / 16, 1.0 / 4};
  EXPECT_TRUE(analyse(m, {12 * 1.001, 16, s}, D).turing_unstable);
  EXPECT_TRUE(analyse(m, {12, 16 * 0.999, s}, D).turing_unstable);
  for (const auto& r : {analyse(m, {12 * 0.999, 16, s}, D), analyse(m, {12, 16 * 1.001, s}, D)}) {
    EXPECT_TRUE(r.stable_homogeneous);
    EXPECT_FALSE(r.turing_unstable);
    EXPECT_FALSE(r.marginal);
  }
  // beta <= alpha: no homogeneous state.
  const auto none = analyse(m, {16, 12, s}, D);
  EXPECT_FALSE(none.has_steady_state);
  EXPECT_EQ(summary(none), "no homogeneous steady state");
}

TEST(TuringModel, FastestAllowedModeOfPeriodicGrid) {
  // 256^2, h = 1, 5pt: the fastest allowed mode is m = (12, 8) (or (8, 12)): 256/sqrt(208) =
  // 17.75; checked against a brute-force scan with laplacian_q and growth_at_q.
  const auto& m = model("turing");
  DiscreteGrid grid;
  grid.n = {256, 256, 1};
  StabilityOptions o;
  o.grid = grid;
  const auto r = analyse(m, default_params(m), default_diffusion(m), o);
  const auto best = fastest_allowed_mode(r, grid);
  EXPECT_EQ(best.scanned, 129 * 129 - 1);
  EXPECT_EQ(best.m[0] * best.m[0] + best.m[1] * best.m[1], 208);
  EXPECT_NEAR(best.wavelength, 256 / sqrt(208.0), 1e-12);
  EXPECT_TRUE(contains(summary(best), "wavelength 17.75")) << summary(best);
  double brute = -1e300;
  const auto kx = allowed_wavenumbers(grid, 0);
  for (double a : kx)
    for (double b : kx)
      if (a > 0 || b > 0)
        brute = std::max(brute, growth_at_q(r, laplacian_q(&grid, {a, b, 0})).growth);
  EXPECT_NEAR(best.growth, brute, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// Discrete symbols.

TEST(DiscreteSymbol, ApproachesContinuousAsHShrinks) {
  // Brusselator default; the same physical problem on grids of spacing h: the fastest k and its
  // growth converge to the continuous values at second order (error ratio ~4 per halving,
  // accepted in [3.5, 4.5]), below 1e-3 relative at h = 1/8. 5pt along x, 9pt along the
  // diagonal, 7pt (3-D) along (1, 2, 2)/3.
  const auto& m = model("brusselator");
  const auto cont = analyse(m, default_params(m), default_diffusion(m));
  struct Case {
    int dim;
    const char* stencil;
    std::array<double, 3> dir;
  };
  for (const Case& c :
       {Case{2, "5pt", {1, 0, 0}}, Case{2, "9pt", {1, 1, 0}}, Case{3, "7pt", {1, 2, 2}}}) {
    double prev = 0;
    for (double h : {2.0, 1.0, 0.5, 0.25, 0.125}) {
      StabilityOptions o;
      o.grid = DiscreteGrid{c.dim, {h, h, h}, {0, 0, 0}, {true, true, true}, c.stencil};
      o.direction = c.dir;
      const auto r = analyse(m, default_params(m), default_diffusion(m), o);
      const double err = rel(r.k_fastest, cont.k_fastest);
      if (prev > 0) {
        EXPECT_GT(prev / err, 3.5) << c.stencil << " h " << h;
        EXPECT_LT(prev / err, 4.5) << c.stencil << " h " << h;
      }
      prev = err;
      if (h == 0.125) {
        EXPECT_LT(err, 1e-3) << c.stencil;
        EXPECT_LT(rel(r.growth_fastest, cont.growth_fastest), 1e-3) << c.stencil;
      }
    }
  }
}

TEST(DiscreteSymbol, NinePointAlongAxisEqualsFivePoint) {
  // Along an axis the 9pt symbol is 2 (1 - cos kh) / h^2, the 5pt one's (1e-13).
  DiscreteGrid g5, g9;
  g9.stencil = "9pt";
  g5.h = g9.h = {0.7, 0.7, 1};
  for (double k : {0.1, 1.0, 3.0, 4.4})
    EXPECT_NEAR(laplacian_q(&g5, {k, 0, 0}), laplacian_q(&g9, {k, 0, 0}), 1e-13);
  EXPECT_NEAR(laplacian_q(&g5, {1, 0, 0}), 4 / 0.49 * std::pow(std::sin(0.35), 2), 1e-13);
  EXPECT_EQ(laplacian_q(nullptr, {1, 2, 2}), 9.0);
}

TEST(AllowedModes, WavenumbersOfPeriodicAndZeroFluxAxes) {
  DiscreteGrid g;
  g.n = {8, 4, 1};
  g.h = {0.5, 1, 1};
  g.periodic = {true, false, true};
  const auto kx = allowed_wavenumbers(g, 0), ky = allowed_wavenumbers(g, 1);
  ASSERT_EQ(kx.size(), 5u); // 2 pi m / 4, m = 0..4
  ASSERT_EQ(ky.size(), 4u); // pi m / 4, m = 0..3
  for (int mm = 0; mm < 5; ++mm)
    EXPECT_NEAR(kx[mm], 2 * kPi * mm / 4, 1e-15);
  for (int mm = 0; mm < 4; ++mm)
    EXPECT_NEAR(ky[mm], kPi * mm / 4, 1e-15);
}

// ---------------------------------------------------------------------------------------------
// General N, forward Euler rates, steady states of every model.

TEST(GeneralN, DecoupledThirdSpeciesChangesNothing) {
  // Brusselator default plus a decoupled decaying species (J33 = -1, D3 = 1); and the 2-species
  // problem through the general eigenvalue path. Same growth (1e-12), band (1e-8) and k_fastest
  // (1e-7: a flat maximum amplifies round-off differences).
  const double J2[4] = {8, 9, -9, -9}, D2[2] = {49.4, 117.6};
  const double J3[9] = {8, 9, 0, -9, -9, 0, 0, 0, -1}, D3[3] = {49.4, 117.6, 1};
  const auto r2 = analyse_jacobian(2, J2, D2);
  StabilityOptions o3, og;
  o3.k_max = r2.k_max;
  og.general_eigensolver = true;
  const auto r3 = analyse_jacobian(3, J3, D3, o3);
  const auto rg = analyse_jacobian(2, J2, D2, og);
  for (const auto* r : {&r3, &rg}) {
    EXPECT_TRUE(r->turing_unstable);
    EXPECT_LT(rel(r->k_fastest, r2.k_fastest), 1e-7);
    EXPECT_LT(rel(r->growth_fastest, r2.growth_fastest), 1e-12);
    EXPECT_LT(rel(r->k_lo, r2.k_lo), 1e-8);
    EXPECT_LT(rel(r->k_hi, r2.k_hi), 1e-8);
  }
}

TEST(GeneralN, WaveInstabilityOfThreeSpecies) {
  // A 3-species system stable at k = 0 whose fastest mode is an oscillatory pair (a wave
  // instability, impossible with 2 species and D >= 0); checked against direct eigenvalues.
  const double J[9] = {0, 1.5, -1, -1, 0.5, 1.5, 0.5, 0.5, -1.5}, D[3] = {0, 0.25, 1};
  const auto r = analyse_jacobian(3, J, D);
  EXPECT_TRUE(r.stable_homogeneous);
  EXPECT_TRUE(r.turing_unstable);
  EXPECT_TRUE(r.oscillatory_fastest);
  EXPECT_TRUE(starts_with(summary(r), "wave-unstable")) << summary(r);
  double A[9];
  std::copy(J, J + 9, A);
  for (int s = 0; s < 3; ++s)
    A[4 * s] -= r.k_fastest * r.k_fastest * D[s];
  const auto ev = sorted_eigs(3, A, true);
  EXPECT_NEAR(ev[2].real(), r.growth_fastest, 1e-12);
  EXPECT_NEAR(std::abs(ev[2].imag()), r.frequency_fastest, 1e-12);
  EXPECT_GT(r.frequency_fastest, 0.1);
}

TEST(ForwardEuler, RatesOfTheStepMap) {
  // With dt, sigma = ln|1 + dt lambda| / dt (1e-14); dt -> 0 recovers sigma (1e-5 at 1e-5).
  // On the h = 1 grid along the diagonal (q up to 8 at the corner), dt below the explicit bound
  // 2 / (8 D_max) slightly lowers the fastest growth; above it the Nyquist corner grows fastest.
  const auto& m = model("brusselator");
  const auto c = analyse(m, default_params(m), default_diffusion(m));
  StabilityOptions o;
  o.dt = 0.01;
  const auto e = analyse(m, default_params(m), default_diffusion(m), o);
  const double q = 0.05;
  double A[4] = {8 - q * 49.4, 9, -9, -9 - q * 117.6};
  const auto ev = sorted_eigs(2, A, false);
  double want = -1e300;
  for (const auto& l : ev)
    want = std::max(want, std::log(std::abs(1.0 + 0.01 * l)) / 0.01);
  EXPECT_NEAR(growth_at_q(e, q).growth, want, 1e-14);
  o.dt = 1e-5;
  const auto tiny = analyse(m, default_params(m), default_diffusion(m), o);
  EXPECT_LT(rel(tiny.growth_fastest, c.growth_fastest), 1e-5);

  const double bound = 2 / (8 * 117.6);
  o.grid = DiscreteGrid{};
  o.direction = {1, 1, 0};
  o.dt = 0;
  const auto g = analyse(m, default_params(m), default_diffusion(m), o);
  o.dt = 0.9 * bound;
  const auto ok = analyse(m, default_params(m), default_diffusion(m), o);
  o.dt = 1.1 * bound;
  const auto bad = analyse(m, default_params(m), default_diffusion(m), o);
  EXPECT_LT(ok.growth_fastest, g.growth_fastest);
  EXPECT_LT(rel(ok.k_fastest, g.k_fastest), 1e-2);
  EXPECT_NEAR(bad.k_fastest, kPi * sqrt(2.0), 1e-6); // a flat maximum: ~sqrt(eps)
  EXPECT_TRUE(bad.band_open);
  EXPECT_GT(bad.growth_fastest, 10 * g.growth_fastest);
}

TEST(SteadyStates, EveryModelsStatesAreRoots) {
  // For every registered model at its defaults: each state found has |R| <= 1e-9 and the
  // model's own steady_state is among them; Turing and Brusselator have exactly one.
  for (const auto& m : model_registry()) {
    const auto p = default_params(m);
    const auto states = find_steady_states(m, p);
    std::vector<double> own(m.nspecies), R(m.nspecies);
    const bool has_own = m.steady_state(p.data(), own.data());
    bool found_own = !has_own;
    for (const auto& u : states) {
      m.rates(u.data(), p.data(), R.data());
      for (double r : R)
        EXPECT_LT(std::abs(r), 1e-9) << m.name;
      double d = 0;
      for (int s = 0; s < m.nspecies; ++s)
        d = std::max(d, std::abs(u[s] - (has_own ? own[s] : 0)));
      found_own = found_own || d < 1e-8;
    }
    EXPECT_TRUE(found_own) << m.name;
    if (std::string(m.name) == "turing" || std::string(m.name) == "brusselator") {
      EXPECT_EQ(states.size(), 1u) << m.name;
    }
  }
}

TEST(Summary, FlatOrDecreasingCurvesReportTheUniformMode) {
  // Gray-Scott's trivial state decays slowest at k = 0 (-F); Barkley's B does not diffuse, so
  // sigma = -1 at every k: both report k_fastest = 0 exactly, not a round-off artefact.
  const auto& gs = model("gray_scott");
  const auto r = analyse(gs, default_params(gs), default_diffusion(gs));
  EXPECT_EQ(r.k_fastest, 0.0);
  EXPECT_EQ(summary(r), "stable: slowest decay -0.04 (uniform mode, k = 0)");
  const auto& b = model("barkley");
  EXPECT_EQ(analyse(b, default_params(b), default_diffusion(b)).k_fastest, 0.0);
}

TEST(Summary, DefaultModelsOneLine) {
  for (const auto& m : model_registry()) {
    const auto s = summary(analyse(m, default_params(m), default_diffusion(m)));
    EXPECT_FALSE(s.empty());
    EXPECT_EQ(s.find('\n'), std::string::npos) << m.name;
  }
}

} // namespace
