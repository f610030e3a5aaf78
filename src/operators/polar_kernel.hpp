// Solution-dependent diffusion coefficients (pure kernels: no PETSc, MPI, allocation or
// exceptions; shared by the coefficient refresh, tests and a device path).
//
// Polar anisotropy (stable-ARD eqs. 14-17): du/dt = div(a(theta) grad u) with theta the angle of
// the local gradient's x-y projection, theta = atan2(du/dy, du/dx) (0 where the gradient
// vanishes: no NaN; the diffusion there is zero anyway). With phi = theta + theta0:
//   witkin_kass (eq. 15): a = alpha + (a_n - alpha)/2 (1 + cos 4 phi), alpha = (a1 + a2)/4,
//                         a_n = a1 on the lobes about phi = 0, pi; a2 about phi = pi/2, 3pi/2.
//   cosine (eq. 16):      a = a_n/2 (1 + cos j phi) on lobe n = 1..j, the 2pi/j slice centred
//                         at phi = 2 pi (n - 1) / j (the paper's printed slice bounds
//                         ((n-2) pi/j, n pi/j] overlap and put half the lobes at a cosine
//                         minimum: read as |phi - 2 pi (n-1)/j| <= pi/j). a is continuous (0 at
//                         the slice edges) and peaks at a_n in the lobe's centre.
// max over theta of a: max_n a_n (cosine), max(a1, a2, alpha) (Witkin-Kass).
//
// Gradient-shaped tensor (Sanderson et al. 2006 eqs. 18-19): principal diffusivities
//   l1 + dl along e1, l2 - dl along e2 (l3 unchanged in 3-D),
//   dl = I (grad u / |grad u|) . (v / |v|),  dl = 0 where grad u = 0 or v = 0 (no NaN).
#pragma once

#include "models/model.hpp" // MG_HD

#include <cmath>

namespace morphogen {

constexpr int kMaxPolarLobes = 16;

struct PolarLobes {
  bool witkin_kass = false;
  int j = 4;                        // lobes (cosine form); 4 for Witkin-Kass
  double a[kMaxPolarLobes] = {1.0}; // speeds: a_1..a_j (cosine) or a1, a2 (Witkin-Kass)

  // a(phi), phi = theta + theta0 (any real).
  MG_HD double operator()(double phi) const {
    constexpr double two_pi = 6.283185307179586476925286766559;
    if (witkin_kass) {
      const double alpha = 0.25 * (a[0] + a[1]);
      const double c = std::cos(4.0 * phi);
      // Lobe of phi: a1 where cos 2 phi >= 0 (about 0, pi), a2 elsewhere.
      const double an = std::cos(2.0 * phi) >= 0.0 ? a[0] : a[1];
      return alpha + 0.5 * (an - alpha) * (1.0 + c);
    }
    double n = std::floor(phi * j / two_pi + 0.5);            // nearest lobe centre 2 pi n / j
    n -= j * std::floor(n / j);                               // 0..j-1
    const int ni = n >= 0 && n < j ? static_cast<int>(n) : 0; // 0 for a non-finite phi
    return 0.5 * a[ni] * (1.0 + std::cos(j * phi));
  }
  MG_HD double max() const {
    double m = witkin_kass ? 0.25 * (a[0] + a[1]) : 0.0;
    for (int n = 0; n < (witkin_kass ? 2 : j); ++n)
      m = a[n] > m ? a[n] : m;
    return m;
  }
};

// theta of the gradient g (x, y components).
MG_HD inline double gradient_angle(const double* g) {
  return std::atan2(g[1], g[0]);
}

// dl of eq. 18 for gradient g and direction v (Dim components).
template <int Dim> MG_HD inline double shaped_dlambda(const double* g, const double* v, double I) {
  double gg = 0, vv = 0, gv = 0;
  for (int a = 0; a < Dim; ++a) {
    gg += g[a] * g[a];
    vv += v[a] * v[a];
    gv += g[a] * v[a];
  }
  if (!(gg > 0) || !(vv > 0)) return 0.0;
  const double c = gv / std::sqrt(gg * vv);
  return I * (c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c);
}

// Symmetric tensor components (2-D xx, xy, yy; 3-D xx, xy, xz, yy, yz, zz) of
// l1 e1 e1^T + l2 e2 e2^T (+ l3 e3 e3^T), e the orthonormal frame (rows of `e`, Dim x 3).
template <int Dim>
MG_HD inline void principal_tensor(const double (*e)[3], const double* l, double* s) {
  int q = 0;
  for (int a = 0; a < Dim; ++a)
    for (int b = a; b < Dim; ++b) {
      double v = 0;
      for (int n = 0; n < Dim; ++n)
        v += l[n] * e[n][a] * e[n][b];
      s[q++] = v;
    }
}

// The frame of angles theta (from x, in the x-y plane) and phi (from z; 3-D): e1 =
// (cos t sin p, sin t sin p, cos p), e2 = (-sin t, cos t, 0), e3 = e1 x e2 (as -tensor_theta/phi).
MG_HD inline void principal_frame(double theta, double phi, double (*e)[3]) {
  const double c = std::cos(theta), sn = std::sin(theta), sp = std::sin(phi), cp = std::cos(phi);
  e[0][0] = c * sp, e[0][1] = sn * sp, e[0][2] = cp;
  e[1][0] = -sn, e[1][1] = c, e[1][2] = 0.0;
  e[2][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
  e[2][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
  e[2][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
}

} // namespace morphogen
