// Closed-form Turing analysis of two species: see turing_2x2.hpp for the equations.
#include "analysis/turing_2x2.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen::analysis {

namespace {

// Real roots of A x^2 + B x + C = 0 without cancellation; returns their number (0 to 2).
int real_roots(double A, double B, double C, double* x) {
  if (A == 0) {
    if (B == 0) return 0;
    x[0] = -C / B;
    return 1;
  }
  const double disc = B * B - 4 * A * C;
  if (disc < 0) return 0;
  const double t = -0.5 * (B + std::copysign(std::sqrt(disc), B));
  if (t == 0) {
    x[0] = 0;
    return 1;
  }
  x[0] = t / A;
  x[1] = C / t;
  return 2;
}

// The maximum of sigma on [lo, hi] by golden section (the fallback).
double golden_q(const double* J, const double* D, double lo, double hi) {
  const double r = 0.5 * (std::sqrt(5.0) - 1);
  double c = hi - r * (hi - lo), d = lo + r * (hi - lo);
  double fc = growth_2x2(J, D, c), fd = growth_2x2(J, D, d);
  for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; ++it) {
    if (fc >= fd) {
      hi = d, d = c, fd = fc, c = hi - r * (hi - lo), fc = growth_2x2(J, D, c);
    } else {
      lo = c, c = d, fc = fd, d = lo + r * (hi - lo), fd = growth_2x2(J, D, d);
    }
  }
  return fc >= fd ? c : d;
}

} // namespace

double growth_2x2(const double* J, const double* D, double q) {
  const double a = J[0] - q * D[0], d = J[3] - q * D[1];
  const double half = 0.5 * (a + d), dh = 0.5 * (a - d);
  const double disc = dh * dh + J[1] * J[2];
  return disc >= 0 ? half + std::sqrt(disc) : half;
}

Turing2x2 turing_2x2(const double* J, const double* D, double zero_tol) {
  Turing2x2 r;
  if (!(D[0] > 0) || !(D[1] > 0)) return r;
  r.handled = true;
  const double a = J[0], b = J[1], c = J[2], d = J[3];
  r.tol = zero_tol * std::max(std::abs(a) + std::abs(b), std::abs(c) + std::abs(d));
  r.growth0 = growth_2x2(J, D, 0.0);
  r.growth_fastest = r.growth0;
  r.stable_homogeneous = r.growth0 < -r.tol;
  if (!r.stable_homogeneous) return r;
  const double S = D[0] + D[1], P = D[0] * D[1], h = a * D[1] + d * D[0];
  const double T0 = a + d, det0 = a * d - b * c;
  if (!(h > 0) || !(h * h > 4 * P * det0)) return r; // Delta(q) >= 0 for every q >= 0
  const double dD = D[0] - D[1];
  double q[2];
  const int nq =
      real_roots(-P * dD * dD, 2 * P * (S * T0 - 2 * h), h * h - S * T0 * h + S * S * det0, q);
  double best_q = 0, best = -INFINITY;
  for (int i = 0; i < nq; ++i)
    if (q[i] > 0 && std::isfinite(q[i]))
      if (const double g = growth_2x2(J, D, q[i]); g > best) best = g, best_q = q[i];
  if (!(best > 0)) { // round-off: search the band Delta(q) < 0 instead
    const double mid = h / (2 * P), half = std::sqrt(h * h - 4 * P * det0) / (2 * P);
    best_q = golden_q(J, D, std::max(0.0, mid - half), mid + half);
    best = growth_2x2(J, D, best_q);
  }
  if (best > r.tol) {
    r.turing_unstable = true;
    r.q_fastest = best_q;
    r.growth_fastest = best;
  }
  return r;
}

} // namespace morphogen::analysis
