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
#include "app/model_registry.hpp"
#include "core/user_error.hpp"
#include "grid/stencil.hpp"

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
  // By real part rounded to 1e-8 (a conjugate pair's real parts may differ in the last bits,
  // e.g. in a Debug build), then by imaginary part.
  const auto key = [](std::complex<double> z) { return std::llround(z.real() * 1e8); };
  std::sort(ev.begin(), ev.end(), [&](auto a, auto b) {
    return key(a) != key(b) ? key(a) < key(b) : a.imag() < b.imag();
  });
  return ev;
}

// ---------------------------------------------------------------------------------------------
// Eigenvalues: the general path (LAPACK dgeev) against the closed form and against matrices
// with known spectra, up to 6 species.

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

TEST(Eigenvalues, RepeatedRoots) {
  // A defective double root is found to ~sqrt(eps) (its conditioning); a diagonal triple one
  // exactly enough.
  const double D2[4] = {2, 1, 0, 2}, D3[9] = {2, 0, 0, 0, 2, 0, 0, 0, 2};
  for (const auto& l : sorted_eigs(2, D2, true))
    EXPECT_LT(std::abs(l - 2.0), 1e-7);
  for (const auto& l : sorted_eigs(3, D3, true))
    EXPECT_LT(std::abs(l - 2.0), 1e-4);
}

TEST(Eigenvalues, KnownSpectrum6x6) {
  // B = blockdiag([[-1, -2], [2, -1]], [[0.3, 5], [-5, 0.3]], 0.5, -3), A = V B V^-1 with
  // V = I + N (N strictly upper triangular: V^-1 = sum_k (-N)^k, k < 6).
  const int n = 6;
  std::vector<double> B(36, 0.0), N(36, 0.0);
  const double blocks[8] = {-1, -2, 2, -1, 0.3, 5, -5, 0.3};
  for (int b = 0; b < 2; ++b)
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        B[(2 * b + i) * n + 2 * b + j] = blocks[4 * b + 2 * i + j];
  B[4 * n + 4] = 0.5, B[5 * n + 5] = -3;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      N[i * n + j] = 0.25 * ((i + 2 * j) % 5) - 0.5;
  auto mul = [&](const std::vector<double>& X, const std::vector<double>& Y) {
    std::vector<double> Z(36, 0.0);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < n; ++l)
          Z[i * n + j] += X[i * n + l] * Y[l * n + j];
    return Z;
  };
  std::vector<double> V(36, 0.0), Vi(36, 0.0), P(36, 0.0);
  for (int i = 0; i < n; ++i)
    P[i * n + i] = 1; // (-N)^0
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 36; ++i)
      Vi[i] += P[i];
    P = mul(P, N);
    for (double& x : P)
      x = -x;
  }
  for (int i = 0; i < 36; ++i)
    V[i] = N[i] + (i % (n + 1) == 0 ? 1.0 : 0.0);
  const auto A = mul(mul(V, B), Vi);
  const auto ev = sorted_eigs(n, A.data(), true);
  const std::complex<double> want[6] = {-3, {-1, -2}, {-1, 2}, {0.3, -5}, {0.3, 5}, 0.5};
  for (int i = 0; i < n; ++i)
    EXPECT_LT(std::abs(ev[i] - want[i]), 1e-11) << i << ": " << ev[i];
}

TEST(LinearStability, SixSpeciesDecoupledEqualsItsBlocks) {
  // Three decoupled 2-species systems (the Turing model's Jacobian at three parameter sets):
  // the 6-species analysis gives the largest growth of the three 2-species ones at every q.
  const auto& m = model("turing");
  const std::vector<std::vector<double>> sets = {
      {12, 16, 1.0 / 128}, {10, 16, 1.0 / 64}, {12, 20, 1.0 / 128}};
  const std::vector<double> D2 = {0.25, 0.0625};
  std::vector<double> J6(36, 0.0), D6;
  std::vector<StabilityResult> parts;
  for (int b = 0; b < 3; ++b) {
    const auto r = analyse(m, sets[b], D2);
    ASSERT_TRUE(r.has_steady_state) << b;
    parts.push_back(r);
    for (int i = 0; i < 2; ++i) {
      D6.push_back(D2[i]);
      for (int j = 0; j < 2; ++j)
        J6[(2 * b + i) * 6 + 2 * b + j] = r.jacobian[2 * i + j];
    }
  }
  const auto r6 = analyse_jacobian(6, J6.data(), D6.data(), StabilityOptions{});
  for (double q : {0.0, 0.1, 0.5, 1.0, 2.0, 5.0}) {
    double want = -1e300;
    for (const auto& p : parts)
      want = std::max(want, growth_at_q(p, q).growth);
    EXPECT_NEAR(growth_at_q(r6, q).growth, want, 1e-12 * (1 + std::abs(want))) << "q = " << q;
  }
  EXPECT_EQ(r6.turing_unstable,
            parts[0].turing_unstable || parts[1].turing_unstable || parts[2].turing_unstable);
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

// ---------------------------------------------------------------------------------------------
// Per-species (anisotropic) operators.
//
// A tensor Sigma on a 3x3 box (the symbol of the header): centre -2 S11/hx^2 - 2 S22/hy^2, x
// neighbours S11/hx^2, y neighbours S22/hy^2, corners +-S12 / (2 hx hy) (+ on the (1, 1)
// diagonal). Continuous theory, A(k) = J - diag(k^T S_s k): along a unit direction e the problem
// is the isotropic one with D_s' = e^T S_s e. For a 2 x 2 system A = J - kappa^2 diag(Da', Db')
// = J - kappa'^2 diag(1, Db'/Da') with kappa'^2 = Da' kappa^2, so the largest growth along e
// depends only on rho(e) = Db'/Da' (and grows with it for Turk's activator-inhibitor J), and the
// fastest |k| is kappa'_f(rho) / sqrt(Da'). In particular:
//   * one tensor shared by both species (S_s = D_s Sigma): rho = Db/Da in every direction, the
//     same maximum growth everywhere (a tie: the analysis keeps opt.direction), and the fastest
//     |k| along e is k_iso / sqrt(e^T Sigma e), longest along the eigenvector of Sigma's SMALLER
//     eigenvalue;
//   * isotropic activator Da I and inhibitor Db Sigma: rho(e) = (Db/Da) e^T Sigma e, largest
//     along the eigenvector of Sigma's LARGER eigenvalue: the fastest direction, with the growth
//     and k of the isotropic problem with D' = (Da, Db lambda_max).

SpeciesOperator scaled_stencil(const std::string& name, int dim, const std::array<double, 3>& h,
                               double D) {
  Stencil st;
  EXPECT_TRUE(make_stencil(name, dim, h.data(), st));
  SpeciesOperator op;
  for (int t = 0; t < st.nterms; ++t) {
    op.off.push_back(st.off[t]);
    op.w.push_back(D * st.w[t]);
  }
  return op;
}

struct Tensor2 {
  double s11, s22, s12;
};
// D R(theta) diag(l1, l2) R(theta)^T: l1 along (cos theta, sin theta).
Tensor2 rotated(double D, double l1, double l2, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {D * (l1 * c * c + l2 * s * s), D * (l1 * s * s + l2 * c * c), D * (l1 - l2) * c * s};
}
SpeciesOperator box_operator(const Tensor2& S, double hx, double hy) {
  SpeciesOperator op;
  auto add = [&](int dx, int dy, double w) {
    op.off.push_back({dx, dy, 0});
    op.w.push_back(w);
  };
  add(0, 0, -2 * S.s11 / (hx * hx) - 2 * S.s22 / (hy * hy));
  add(-1, 0, S.s11 / (hx * hx));
  add(1, 0, S.s11 / (hx * hx));
  add(0, -1, S.s22 / (hy * hy));
  add(0, 1, S.s22 / (hy * hy));
  const double c = S.s12 / (2 * hx * hy);
  add(1, 1, c);
  add(-1, -1, c);
  add(1, -1, -c);
  add(-1, 1, -c);
  return op;
}
double quad(const Tensor2& S, double ex, double ey) {
  return S.s11 * ex * ex + 2 * S.s12 * ex * ey + S.s22 * ey * ey;
}
DiscreteGrid grid2(double h, long long n = 0) {
  DiscreteGrid g;
  g.h = {h, h, 1};
  g.n = {n, n, 1};
  return g;
}
double angle_diff(double a, double b) { // modulo pi
  double d = std::fmod(std::abs(a - b), kPi);
  return std::min(d, kPi - d);
}

TEST(SpeciesOperators, BoxSymbolIsTheTensorFormula) {
  // operator_q of the box stencil equals the header's formula (1e-13 relative).
  const Tensor2 S = rotated(0.3, 2, 0.5, kPi / 6);
  const double hx = 0.5, hy = 0.25;
  const auto op = box_operator(S, hx, hy);
  for (const auto& k : {std::array<double, 3>{0.3, 0.7, 0}, {-1.1, 2.5, 0}, {4, -6, 0}}) {
    const double want = S.s11 * 4 * std::pow(std::sin(k[0] * hx / 2), 2) / (hx * hx) +
                        S.s22 * 4 * std::pow(std::sin(k[1] * hy / 2), 2) / (hy * hy) +
                        2 * S.s12 * std::sin(k[0] * hx) * std::sin(k[1] * hy) / (hx * hy);
    EXPECT_LT(rel(operator_q(op, {hx, hy, 1}, k), want), 1e-13);
  }
}

TEST(SpeciesOperators, DTimesGridStencilReproducesGridResultsExactly) {
  // Turk's D = (1/16, 1/4) are powers of two, so D_s * w_t is exact and the per-species
  // symbols are bit for bit D_s q: every result equals the analysis without operators (the
  // direction search ties and keeps opt.direction). At the defaults (marginal) and 0.1 % above
  // (Turing-unstable, with a band); 5pt at h = 1 and 0.5 along x and the diagonal, 9pt.
  const auto& m = model("turing");
  const auto D = default_diffusion(m);
  ASSERT_EQ(D, (std::vector<double>{1.0 / 16, 1.0 / 4}));
  struct Case {
    const char* stencil;
    double h;
    std::array<double, 3> dir;
  };
  for (const auto& p : {default_params(m), std::vector<double>{12 * 1.001, 16, 1.0 / 128}})
    for (const Case& c : {Case{"5pt", 1, {1, 0, 0}}, Case{"5pt", 0.5, {1, 0, 0}},
                          Case{"5pt", 1, {1, 1, 0}}, Case{"9pt", 1, {1, 0, 0}}}) {
      StabilityOptions o;
      o.grid = grid2(c.h, 64);
      o.grid->stencil = c.stencil;
      o.direction = c.dir;
      const auto g = analyse(m, p, D, o);
      for (int s = 0; s < 2; ++s)
        o.operators.push_back(scaled_stencil(c.stencil, 2, o.grid->h, D[s]));
      const auto r = analyse(m, p, D, o);
      const std::string what =
          std::string(c.stencil) + " h " + std::to_string(c.h) + " alpha " + std::to_string(p[0]);
      EXPECT_EQ(r.operators.size(), 2u);
      EXPECT_EQ(r.k_fastest, g.k_fastest) << what;
      EXPECT_EQ(r.growth_fastest, g.growth_fastest) << what;
      EXPECT_EQ(r.frequency_fastest, g.frequency_fastest) << what;
      EXPECT_EQ(r.wavelength_fastest, g.wavelength_fastest) << what;
      EXPECT_EQ(r.stable_homogeneous, g.stable_homogeneous) << what;
      EXPECT_EQ(r.turing_unstable, g.turing_unstable) << what;
      EXPECT_EQ(r.marginal, g.marginal) << what;
      EXPECT_EQ(r.hopf, g.hopf) << what;
      EXPECT_EQ(r.oscillatory_fastest, g.oscillatory_fastest) << what;
      EXPECT_EQ(r.has_band, g.has_band) << what;
      EXPECT_EQ(r.k_lo, g.k_lo) << what;
      EXPECT_EQ(r.k_hi, g.k_hi) << what;
      EXPECT_EQ(r.band_open, g.band_open) << what;
      EXPECT_EQ(r.k_max, g.k_max) << what;
      ASSERT_EQ(r.curve.size(), g.curve.size());
      for (size_t i = 0; i < r.curve.size(); ++i)
        ASSERT_EQ(r.curve[i].growth, g.curve[i].growth) << what << " sample " << i;
      EXPECT_EQ(r.direction, g.direction) << what;
      EXPECT_EQ(r.k_vector_fastest, g.k_vector_fastest) << what;
      EXPECT_NEAR(r.direction_fastest, c.dir[1] > 0 ? kPi / 4 : 0, 1e-15) << what;
      EXPECT_EQ(g.turing_unstable, p[0] > 12) << what;
      // growth_at_k with operators = growth_at_q of the grid symbol (exact).
      for (const auto& k : {std::array<double, 3>{0.3, 0.1, 0}, {0.2, -0.25, 0}}) {
        const auto a = growth_at_k(r, k), b = growth_at_q(g, laplacian_q(&*o.grid, k));
        EXPECT_EQ(a.growth, b.growth);
        EXPECT_EQ(growth_at_k(g, k).growth, b.growth);
      }
      // The allowed modes (a different evaluation of the symbol: round-off only). Both stencils
      // are symmetric under each axis' reflection: no sign combinations are scanned.
      const auto ma = fastest_allowed_mode(g, *o.grid), mb = fastest_allowed_mode(r, *o.grid);
      EXPECT_EQ(mb.scanned, 33 * 33 - 1) << what;
      EXPECT_EQ(mb.m[0] * mb.m[0] + mb.m[1] * mb.m[1], ma.m[0] * ma.m[0] + ma.m[1] * ma.m[1]);
      EXPECT_NEAR(mb.growth, ma.growth, 1e-15) << what;
      EXPECT_TRUE(std::isnan(mb.q));
    }
  // Brusselator (D not powers of two): the same to round-off.
  const auto& b = model("brusselator");
  StabilityOptions o;
  o.grid = grid2(1);
  const auto g = analyse(b, default_params(b), default_diffusion(b), o);
  for (double Ds : default_diffusion(b))
    o.operators.push_back(scaled_stencil("5pt", 2, o.grid->h, Ds));
  const auto r = analyse(b, default_params(b), default_diffusion(b), o);
  EXPECT_TRUE(r.turing_unstable);
  EXPECT_EQ(r.direction, g.direction);
  EXPECT_LT(rel(r.k_fastest, g.k_fastest), 1e-7);
  EXPECT_LT(rel(r.growth_fastest, g.growth_fastest), 1e-12);
  EXPECT_LT(rel(r.k_hi, g.k_hi), 1e-8);
}

TEST(SpeciesOperators, SharedRotatedTensorScalesTheFastestK) {
  // Sigma = R(30 deg) diag(2, 0.5) R^T for both species (S_s = D_s Sigma), Turk's kinetics 1 %
  // above threshold, h = 1/16 (k h ~ 0.03: the box symbol is the continuous one to ~1e-4).
  // Along every direction e: the growth is the isotropic maximum, and the fastest |k| is
  // k_iso / sqrt(e^T Sigma e) (2e-4 relative); over directions (1 deg apart) the fastest |k| is
  // longest at 120 deg (the eigenvector of the smaller eigenvalue 0.5) and shortest at 30 deg.
  const auto& m = model("turing");
  const std::vector<double> p{12 * 1.01, 16, 1.0 / 128};
  const auto D = default_diffusion(m);
  const auto iso = analyse(m, p, D); // continuous, isotropic
  ASSERT_TRUE(iso.turing_unstable);
  const double theta = kPi / 6, h = 1.0 / 16;
  const Tensor2 Sigma = rotated(1, 2, 0.5, theta);
  StabilityOptions o;
  o.grid = grid2(h);
  for (double Ds : D)
    o.operators.push_back(box_operator(rotated(Ds, 2, 0.5, theta), h, h));
  o.directions = 0; // the curve along opt.direction
  double kmax_dir = 0, kmin_dir = 0, kmax = 0, kmin = 1e300;
  for (int deg = 0; deg < 180; ++deg) {
    const double phi = deg * kPi / 180;
    o.direction = {std::cos(phi), std::sin(phi), 0};
    const auto r = analyse(m, p, D, o);
    EXPECT_TRUE(r.turing_unstable);
    EXPECT_NEAR(r.direction_fastest, phi, 1e-14);
    EXPECT_LT(rel(r.growth_fastest, iso.growth_fastest), 1e-4) << deg;
    const double want = iso.k_fastest / sqrt(quad(Sigma, o.direction[0], o.direction[1]));
    EXPECT_LT(rel(r.k_fastest, want), 2e-4) << deg;
    if (r.k_fastest > kmax) kmax = r.k_fastest, kmax_dir = deg;
    if (r.k_fastest < kmin) kmin = r.k_fastest, kmin_dir = deg;
  }
  EXPECT_EQ(kmax_dir, 120);
  EXPECT_EQ(kmin_dir, 30);
  EXPECT_LT(rel(kmax / kmin, 2.0), 1e-3); // sqrt(2 / 0.5)
  // With the direction search: the maximum growth is the same in every direction (a tie to
  // round-off, also on the grid: sigma depends on k only through the shared symbol), so the
  // analysis keeps opt.direction, at its own fastest |k|.
  o.directions = 180;
  o.direction = {0, 1, 0};
  const auto r = analyse(m, p, D, o);
  EXPECT_NEAR(r.direction_fastest, kPi / 2, 1e-15);
  EXPECT_LT(rel(r.k_fastest, iso.k_fastest / sqrt(Sigma.s22)), 2e-4);
  EXPECT_NEAR(r.k_vector_fastest[1], r.k_fastest, 1e-15);
}

TEST(SpeciesOperators, AnisotropicInhibitorSetsTheFastestDirection) {
  // Isotropic activator (Da I, the 5pt stencil), inhibitor Db R(theta) diag(1.5, 0.5) R^T, Turk's
  // defaults (on the isotropic threshold, rho = 4): rho(e) = 4 e^T Sigma e is 6 along theta
  // (Turing-unstable) and 2 across it (stable). The direction search finds theta (0.01 deg) with
  // the growth and |k| of the isotropic continuous problem with D' = (Da, 1.5 Db) (1e-4, h = 1/16),
  // for theta = 30 and -30 deg (reported as 150); k_vector_fastest has the matching signs.
  const auto& m = model("turing");
  const auto p = default_params(m);
  const auto D = default_diffusion(m);
  const auto cont = analyse(m, p, {D[0], 1.5 * D[1]});
  ASSERT_TRUE(cont.turing_unstable);
  const double h = 1.0 / 16;
  for (double theta : {kPi / 6, -kPi / 6}) {
    StabilityOptions o;
    o.grid = grid2(h);
    o.operators = {scaled_stencil("5pt", 2, o.grid->h, D[0]),
                   box_operator(rotated(D[1], 1.5, 0.5, theta), h, h)};
    const auto r = analyse(m, p, D, o);
    const double want = theta > 0 ? theta : theta + kPi;
    EXPECT_TRUE(r.turing_unstable) << summary(r);
    EXPECT_LT(angle_diff(r.direction_fastest, want), 0.01 * kPi / 180)
        << r.direction_fastest * 180 / kPi;
    EXPECT_LT(rel(r.growth_fastest, cont.growth_fastest), 1e-4);
    EXPECT_LT(rel(r.k_fastest, cont.k_fastest), 1e-4);
    EXPECT_NEAR(std::hypot(r.k_vector_fastest[0], r.k_vector_fastest[1]), r.k_fastest, 1e-15);
    EXPECT_GT(r.k_vector_fastest[0] * r.k_vector_fastest[1] * theta, 0); // ky's sign
    EXPECT_TRUE(contains(summary(r), theta > 0 ? "direction 30 deg" : "direction 150 deg"))
        << summary(r);
    // The curve is along the fastest direction: its samples match growth_at_k there.
    const auto& c = r.curve[r.curve.size() / 3];
    EXPECT_EQ(growth_at_k(r, {c.k * r.direction[0], c.k * r.direction[1], 0}).growth, c.growth);
    // Across theta (rho = 2) it is stable: the analysis along that direction alone.
    o.directions = 0;
    o.direction = {-std::sin(theta), std::cos(theta), 0};
    const auto across = analyse(m, p, D, o);
    EXPECT_FALSE(across.turing_unstable);
    EXPECT_LT(across.growth_fastest, 0);
  }
}

TEST(SpeciesOperators, FastestAllowedModeScansTheSignsOfCrossTerms) {
  // The anisotropic inhibitor above on a periodic 128^2 grid, h = 1/2: the fastest allowed mode
  // has kx ky of the sign of theta (continuous theory: the fastest direction is theta; across it
  // the system is stable). Modes with m_d >= 0 only would miss theta = -30 deg altogether. The
  // scan covers (n/2 + 1)^2 - 1 modes plus (n/2 - 1)^2 with ky negated, and its result is the
  // brute-force maximum of growth_at_k over all allowed (kx, ky), either sign (1e-15).
  const auto& m = model("turing");
  const auto p = default_params(m);
  const auto D = default_diffusion(m);
  const double h = 0.5;
  const long long n = 128;
  const DiscreteGrid grid = grid2(h, n);
  for (double theta : {kPi / 6, -kPi / 6}) {
    StabilityOptions o;
    o.grid = grid;
    o.operators = {scaled_stencil("5pt", 2, grid.h, D[0]),
                   box_operator(rotated(D[1], 1.5, 0.5, theta), h, h)};
    const auto r = analyse(m, p, D, o);
    const auto best = fastest_allowed_mode(r, grid);
    EXPECT_EQ(best.scanned, (n / 2 + 1) * (n / 2 + 1) - 1 + (n / 2 - 1) * (n / 2 - 1));
    EXPECT_GT(best.m[0], 0);
    EXPECT_GT(best.m[1] * theta, 0) << "m = (" << best.m[0] << ", " << best.m[1] << ")";
    EXPECT_GT(best.k[1] * theta, 0);
    EXPECT_GT(best.growth, 0);
    // Near the fastest direction and |k| (the allowed modes are 2 pi / 64 apart).
    EXPECT_LT(angle_diff(std::atan2(best.k[1], best.k[0]), r.direction_fastest), 0.15);
    EXPECT_LT(rel(best.k_abs, r.k_fastest), 0.15);
    EXPECT_LE(best.growth, r.growth_fastest);
    const auto ks = allowed_wavenumbers(grid, 0);
    double brute = -1e300, brute_pos = -1e300;
    for (double a : ks)
      for (double b : ks)
        if (a > 0 || b > 0) {
          brute = std::max(brute, growth_at_k(r, {a, b, 0}).growth);
          brute = std::max(brute, growth_at_k(r, {a, -b, 0}).growth);
          brute_pos = std::max(brute_pos, growth_at_k(r, {a, b, 0}).growth);
        }
    EXPECT_NEAR(best.growth, brute, 1e-15);
    EXPECT_NEAR(growth_at_k(r, best.k).growth, best.growth, 1e-15);
    if (theta < 0) {
      EXPECT_LT(brute_pos, 0.5 * best.growth); // the m >= 0 quadrant is slower
    }
  }
}

TEST(SpeciesOperators, FastestAllowedModeSignsIn3D) {
  // 3-D operators with xy and yz cross terms (a 3x3x3 box) and kinetics unstable along a
  // skew direction: the scan (signs up to k ~ -k) equals the brute-force maximum over every
  // allowed (+-kx, +-ky, +-kz) of a 12 x 10 x 8 grid, periodic and zero-flux axes mixed.
  const double J[4] = {3.0 / 8, 4.0 / 8, -4.0 / 8, -4.0 / 8};
  const double D[2] = {1.0 / 16, 1.0 / 2};
  DiscreteGrid grid;
  grid.dim = 3;
  grid.h = {1, 0.8, 1.2};
  grid.n = {12, 10, 8};
  grid.periodic = {true, false, true};
  auto op3 = [&](double Ds, double cxy, double cyz) {
    SpeciesOperator op = scaled_stencil("7pt", 3, grid.h, Ds);
    auto add = [&](int a, int b, int c, double w) {
      op.off.push_back({a, b, c});
      op.w.push_back(w);
      op.off.push_back({-a, -b, -c});
      op.w.push_back(w);
    };
    add(1, 1, 0, cxy), add(1, -1, 0, -cxy), add(0, 1, 1, cyz), add(0, 1, -1, -cyz);
    return op;
  };
  StabilityOptions o;
  o.grid = grid;
  o.operators = {op3(D[0], 0, 0), op3(D[1], 0.08, -0.05)};
  const auto r = analyse_jacobian(2, J, D, o);
  const auto best = fastest_allowed_mode(r, grid);
  std::array<std::vector<double>, 3> ks;
  for (int d = 0; d < 3; ++d)
    ks[d] = allowed_wavenumbers(grid, d);
  double brute = -1e300, brute_pos = -1e300;
  for (double a : ks[0])
    for (double b : ks[1])
      for (double c : ks[2])
        for (int sg = 0; sg < 8; ++sg)
          if (a > 0 || b > 0 || c > 0) {
            const double g =
                growth_at_k(r, {sg & 1 ? -a : a, sg & 2 ? -b : b, sg & 4 ? -c : c}).growth;
            brute = std::max(brute, g);
            if (sg == 0) brute_pos = std::max(brute_pos, g);
          }
  EXPECT_NEAR(best.growth, brute, 1e-15);
  EXPECT_LT(brute_pos, brute - 1e-3); // the signs matter here
  EXPECT_NEAR(growth_at_k(r, best.k).growth, best.growth, 1e-15);
  EXPECT_GT(best.growth, 0);
  EXPECT_GE(best.m[0], 0);
  // Without cross terms every sign gives the same symbol: modes with m_d >= 0 only.
  o.operators = {op3(D[0], 0, 0), op3(D[1], 0, 0)};
  EXPECT_EQ(fastest_allowed_mode(analyse_jacobian(2, J, D, o), grid).scanned, 7 * 10 * 5 - 1);
}

TEST(SpeciesOperators, BadOperatorsAreRejected) {
  const double J[4] = {3.0 / 128, 4.0 / 128, -4.0 / 128, -4.0 / 128};
  const double D[2] = {1.0 / 16, 1.0 / 4};
  StabilityOptions o;
  o.grid = grid2(1);
  o.directions = 0;
  const auto good = box_operator(rotated(1, 2, 0.5, 0.3), 1, 1);
  o.operators = {good};
  EXPECT_THROW(analyse_jacobian(2, J, D, o), UserError); // one operator for two species
  auto asym = good;
  asym.w[5] += 0.1, asym.w[0] -= 0.1; // (1, 1) no longer equals (-1, -1)
  o.operators = {good, asym};
  EXPECT_THROW(analyse_jacobian(2, J, D, o), UserError);
  auto leaky = good;
  leaky.w[0] -= 0.1; // sum w != 0
  o.operators = {good, leaky};
  EXPECT_THROW(analyse_jacobian(2, J, D, o), UserError);
  auto deep = good;
  deep.off.push_back({0, 0, 1}), deep.off.push_back({0, 0, -1});
  deep.w.push_back(0), deep.w.push_back(0); // a z offset in 2-D
  o.operators = {good, deep};
  EXPECT_THROW(analyse_jacobian(2, J, D, o), UserError);
  o.operators = {good, good};
  const auto r = analyse_jacobian(2, J, D, o);
  EXPECT_THROW(growth_at_q(r, 0.1), UserError); // no single q
  o.grid.reset();
  EXPECT_THROW(analyse_jacobian(2, J, D, o), UserError); // no spacings
}

} // namespace
