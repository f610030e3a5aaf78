// Meinhardt's spot formation model as given in Appendix A of "Stable Advection-Reaction-
// Diffusion with Arbitrary Anisotropy" (after Meinhardt):
//   dA/dt = s (p1 A + 0.01 alpha A^2 / B + p3) + D_A lap A
//   dB/dt = s (p2 B + 0.01 alpha A^2)          + D_B lap B
// A is the activator, B the inhibitor; p1 < 0 and p2 < 0 are (minus) their decay rates, p3 a
// basal production of A, alpha the strength of the autocatalysis. With c = 0.01 alpha the
// homogeneous steady state is (from R_B = 0, B = -c A^2 / p2, so c A^2 / B = -p2 in R_A):
//   A* = (p2 - p3) / p1,   B* = -c A*^2 / p2,
// returned only where it exists and is positive (p1, p2 != 0, alpha != 0, A* > 0, B* > 0).
// Substituting B = c B' shows this is Gierer-Meinhardt with alpha_GM = -p1, beta_GM = -p2,
// gamma_GM = p3 and the inhibitor rescaled by c; alpha only scales B.
// The paper gives no values, so the defaults are our choice: s = 1, alpha = 100 (c = 1, so A
// and B are both of order 1), p1 = -1, p2 = -1.5, p3 = 0.05, D_A = 1, D_B = 20. Then
// (A*, B*) = (1.55, 1.601667); without diffusion the state is stable (eigenvalues
// -0.282 +- 1.19i) and with the default D it is Turing-unstable, fastest-growing wavelength
// about 11.6 grid units at unit spacing (growth rate 0.26): a noisy start gives spots.
// B = 0 is a pole, so clamping negatives to 0 would not help, and it is off.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct Meinhardt {
  static constexpr const char* name = "meinhardt";
  static constexpr const char* doc = "Meinhardt's activator-inhibitor spot formation model";
  static constexpr const char* reference =
      "Stable advection-reaction-diffusion with arbitrary anisotropy, Appendix A";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 5;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"A", 1.0, 1.55, "activator"},
      {"B", 20.0, 1.55 * 1.55 / 1.5, "inhibitor"},
  }};
  static constexpr std::array<ParamInfo, 5> params{{
      {"s", 1.0, 0.0, 1e6, "reaction rate (scales pattern size)"},
      {"alpha", 100.0, 0.0, 1e6, "autocatalysis strength (enters as 0.01 alpha)"},
      {"p1", -1.0, -1e6, 0.0, "linear rate of A (negative: decay)"},
      {"p2", -1.5, -1e6, 0.0, "linear rate of B (negative: decay)"},
      {"p3", 0.05, 0.0, 1e6, "basal production of A"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double A = u[0], B = u[1], s = p[0], c = 0.01 * p[1], p1 = p[2], p2 = p[3], p3 = p[4];
    const double cA2 = c * A * A;
    r[0] = s * (p1 * A + cA2 / B + p3);
    r[1] = s * (p2 * B + cA2);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double A = u[0], B = u[1], s = p[0], c = 0.01 * p[1], p1 = p[2], p2 = p[3];
    const double AB = A / B;
    J[0] = s * (p1 + 2.0 * c * AB);
    J[1] = -s * c * AB * AB;
    J[2] = 2.0 * s * c * A;
    J[3] = s * p2;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double c = 0.01 * p[1], p1 = p[2], p2 = p[3], p3 = p[4];
    if (p1 == 0.0 || p2 == 0.0 || c == 0.0) return false;
    const double A = (p2 - p3) / p1;
    const double B = -c * A * A / p2;
    if (!(A > 0.0 && B > 0.0)) return false;
    u[0] = A;
    u[1] = B;
    return true;
  }
};

} // namespace morphogen::models
