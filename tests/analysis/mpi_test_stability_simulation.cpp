// Linear theory against the simulation. The `turing` model at alpha = 12.2, beta = 16,
// s = 1/128, D = (1/16, 1/4) is Turing-unstable (stable without diffusion; the Hopf point is
// alpha ~ 12.47, the Turing threshold alpha = 12). A 128^2 periodic run (h = 1, dt = 0.5, 5pt
// and 9pt) from the steady state u* plus uniform noise in a (+-1e-4) is stopped early, when the
// fastest predicted mode has grown 1000 times in amplitude (about 8,300 steps): the measured
// amplification of its shell must be >= 100 and the field still within 1 % of a* (linear
// regime). The dominant wavelength of a is then measured from its radially averaged power
// spectrum: the peak shell (width 1 in |m|), then the vertex of a parabola in |m| fitted by
// weighted least squares (weights: mode counts) to the logarithm of the exact radial average
// (one point per distinct mx^2 + my^2) within +-1.5 of that shell. It must match the
// wavelength of the fastest-growing allowed mode of the grid predicted by
// analysis/linear_stability (discrete symbol of the run's stencil, forward Euler rates at the
// run's dt) within 5 %. (Seeds 1-8 gave errors of 0.1-1.0 % for the 5pt run; the fit is in |m|
// because ln P is more nearly symmetric about the peak in k than in k^2.) Runs on
// PETSC_COMM_WORLD: the same field on 1 and 2 ranks (the noise is hashed by global cell).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "analysis/linear_stability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

constexpr double kPi = std::numbers::pi;

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// |DFT|^2 of the n x n field f (x fastest) after removing its mean; naive separable DFT
// (n = 128: a few ms).
std::vector<double> power_spectrum(const std::vector<double>& f, int n) {
  double mean = 0;
  for (double v : f)
    mean += v;
  mean /= static_cast<double>(f.size());
  std::vector<std::complex<double>> tw(n), rows(f.size());
  for (int m = 0; m < n; ++m)
    tw[m] = std::polar(1.0, -2 * kPi * m / n);
  for (int j = 0; j < n; ++j)
    for (int mx = 0; mx < n; ++mx) {
      std::complex<double> s = 0;
      for (int i = 0; i < n; ++i)
        s += (f[i + n * j] - mean) * tw[(static_cast<long>(mx) * i) % n];
      rows[mx + n * j] = s;
    }
  std::vector<double> P(f.size());
  for (int mx = 0; mx < n; ++mx)
    for (int my = 0; my < n; ++my) {
      std::complex<double> s = 0;
      for (int j = 0; j < n; ++j)
        s += rows[mx + n * j] * tw[(static_cast<long>(my) * j) % n];
      P[mx + n * my] = std::norm(s);
    }
  return P;
}

// Signed mode numbers of DFT index m.
long signed_mode(int m, int n) {
  return m <= n / 2 ? m : m - n;
}

// Radially averaged spectrum: average power per distinct r2 = mx^2 + my^2 (r2 > 0).
struct Radius {
  double m = 0; // sqrt(r2)
  double power = 0;
  int count = 0;
};
std::vector<Radius> radial_average(const std::vector<double>& P, int n) {
  std::vector<Radius> by_r2(static_cast<size_t>(n) * n / 2 + 1);
  for (int my = 0; my < n; ++my)
    for (int mx = 0; mx < n; ++mx) {
      const long sx = signed_mode(mx, n), sy = signed_mode(my, n), r2 = sx * sx + sy * sy;
      by_r2[r2].m = std::sqrt(static_cast<double>(r2));
      by_r2[r2].power += P[mx + n * my];
      ++by_r2[r2].count;
    }
  std::vector<Radius> out;
  for (size_t r2 = 1; r2 < by_r2.size(); ++r2)
    if (by_r2[r2].count > 0) {
      by_r2[r2].power /= by_r2[r2].count;
      out.push_back(by_r2[r2]);
    }
  return out;
}

// Average power of the width-1 shell round(|m|) = b.
double shell_power(const std::vector<Radius>& rad, long b) {
  double p = 0;
  int c = 0;
  for (const auto& r : rad)
    if (std::lround(r.m) == b) p += r.power * r.count, c += r.count;
  return c > 0 ? p / c : 0;
}

// Dominant |m| (see the header comment); NaN if the fit has no maximum.
double dominant_m(const std::vector<Radius>& rad, int n) {
  long peak = 1;
  for (long b = 1; b <= n / 2; ++b)
    if (shell_power(rad, b) > shell_power(rad, peak)) peak = b;
  double S[5] = {0, 0, 0, 0, 0}, T[3] = {0, 0, 0};
  for (const auto& r : rad) {
    const double x = r.m - static_cast<double>(peak);
    if (std::abs(x) > 1.5) continue;
    double xp = 1;
    for (int p = 0; p < 5; ++p, xp *= x) {
      S[p] += r.count * xp;
      if (p < 3) T[p] += r.count * xp * std::log(r.power);
    }
  }
  // Normal equations of ln P = c0 + c1 x + c2 x^2, by Cramer's rule.
  auto det3 = [](double a, double b, double c, double d, double e, double f, double g, double h,
                 double i) {
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  };
  const double D = det3(S[0], S[1], S[2], S[1], S[2], S[3], S[2], S[3], S[4]);
  const double c1 = det3(S[0], T[0], S[2], S[1], T[1], S[3], S[2], T[2], S[4]) / D;
  const double c2 = det3(S[0], S[1], T[0], S[1], S[2], T[1], S[2], S[3], T[2]) / D;
  if (!(c2 < 0)) return std::nan("");
  return static_cast<double>(peak) - c1 / (2 * c2);
}

void check_early_wavelength(const char* stencil) {
  const int n = 128;
  const double alpha = 12.2, beta = 16, s = 1.0 / 128, Da = 1.0 / 16, Db = 0.25, dt = 0.5;
  const ModelEntry* turing = find_model("turing");
  ASSERT_NE(turing, nullptr);
  analysis::DiscreteGrid grid;
  grid.n = {n, n, 1};
  grid.stencil = stencil;
  analysis::StabilityOptions opt;
  opt.grid = grid;
  opt.dt = dt;
  const auto r = analysis::analyse(*turing, {alpha, beta, s}, {Da, Db}, opt);
  ASSERT_TRUE(r.turing_unstable) << analysis::summary(r);
  const auto mode = analysis::fastest_allowed_mode(r, grid);
  const int steps = static_cast<int>(std::ceil(std::log(1000.0) / mode.growth / dt));

  auto sim = make_sim(PETSC_COMM_WORLD, {{"model", "turing"},
                                         {"grid_n", std::to_string(n) + "," + std::to_string(n)},
                                         {"stencil", stencil},
                                         {"params_alpha", num(alpha)},
                                         {"params_beta", num(beta)},
                                         {"params_s", num(s)},
                                         {"D_a", num(Da)},
                                         {"D_b", num(Db)},
                                         {"init_a", num(r.u_star[0]) + " +- 1e-4"},
                                         {"init_b", num(r.u_star[1])},
                                         {"clamp", "false"},
                                         {"dt", num(dt)}});
  const auto a0 = gather_all(sim->grid(), sim->state()[0]);
  for (int k = 0; k < steps; ++k)
    sim->step();
  const auto a1 = gather_all(sim->grid(), sim->state()[0]);

  bool ok = true;
  if (!a1.empty()) { // rank 0
    double dev = 0;
    for (double v : a1)
      dev = std::max(dev, std::abs(v - r.u_star[0]));
    const auto rad0 = radial_average(power_spectrum(a0, n), n);
    const auto rad1 = radial_average(power_spectrum(a1, n), n);
    const double measured = n / dominant_m(rad1, n); // wavelength in cells (h = 1)
    const long b = std::lround(mode.k_abs * n / (2 * kPi));
    const double gain = std::sqrt(shell_power(rad1, b) / shell_power(rad0, b));
    const double err = std::abs(measured - mode.wavelength) / mode.wavelength;
    std::printf("[%s] %s\n[%s] %s\n[%s] %d steps (t %.0f): shell amplification %.0f, "
                "max |a - a*| %.2e; dominant wavelength %.3f, predicted %.3f (error %.2f %%)\n",
                stencil, analysis::summary(r).c_str(), stencil, analysis::summary(mode).c_str(),
                stencil, steps, steps * dt, gain, dev, measured, mode.wavelength, 100 * err);
    EXPECT_GE(gain, 100) << "not amplified enough for a clean spectrum";
    EXPECT_LT(dev, 0.01 * r.u_star[0]) << "no longer in the linear regime";
    EXPECT_LT(err, 0.05) << "measured " << measured << ", predicted " << mode.wavelength;
    ok = gain >= 100 && dev < 0.01 * r.u_star[0] && err < 0.05;
  }
  EXPECT_TRUE(all_ranks(ok));
}

} // namespace

TEST(StabilitySimulation, EarlyDominantWavelengthIsFastestAllowedMode5pt) {
  check_early_wavelength("5pt");
}

TEST(StabilitySimulation, EarlyDominantWavelengthIsFastestAllowedMode9pt) {
  check_early_wavelength("9pt");
}
