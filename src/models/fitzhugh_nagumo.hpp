// FitzHugh-Nagumo model in the form of Appendix A of "Stable Advection-Reaction-Diffusion
// with Arbitrary Anisotropy" (FitzHugh 1961, Nagumo et al. 1962; the Hagberg-Meron scaling):
//   dA/dt = A - A^3 - B            + D_A lap A
//   dB/dt = eps (A - a1 B - a0)    + D_B lap B
// A is the fast activator, B the slow inhibitor; both are signed (no clamping).
// Homogeneous steady states: B* = A* - A*^3 with A* a real root of the cubic
//   a1 A^3 + (1 - a1) A - a0 = 0.
// steady_state returns the unique real root where there is one (a1 <= 1 always, or |a0|
// large); where there are three (bistable medium) it returns the middle one, the unstable
// state between the two stable branches, from which a noisy start separates into domains.
// Defaults (our choice; the paper gives no values): eps = 0.1, a0 = 0, a1 = 2, D_A = 1,
// D_B = 2. This is the bistable regime with three states A* = -1/sqrt 2, 0, 1/sqrt 2; the
// middle state (0, 0) is a saddle, and from it a noisy start forms a labyrinth of A = +-0.9
// domains with a period of about 25 grid units at unit spacing, which then only rearranges
// slowly (checked for eps = 0.05-0.2 with D_B = 2-4; for eps <= 0.02 one phase takes over).
// With a1 < 1 and the rest state on the left branch (e.g. a1 = 0.5, a0 = -0.5, D_B = 0) the
// medium is excitable instead, and a seeded pulse travels (about 0.9 grid units per time).
#pragma once

#include <cmath>

#include "models/model.hpp"

namespace morphogen::models {

struct FitzHughNagumo {
  static constexpr const char* name = "fitzhugh_nagumo";
  static constexpr const char* doc =
      "FitzHugh-Nagumo model: labyrinths, fronts and travelling waves";
  static constexpr const char* reference =
      "Stable advection-reaction-diffusion with arbitrary anisotropy, Appendix A";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"A", 1.0, 0.0, "fast activator (signed)"},
      {"B", 2.0, 0.0, "slow inhibitor (signed)"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"eps", 0.1, 0.0, 1e3, "time-scale ratio of B to A"},
      {"a0", 0.0, -1e3, 1e3, "offset of the B nullcline (asymmetry between A = +-1)"},
      {"a1", 2.0, 0.0, 1e3, "B self-decay; a1 > 1 can make the medium bistable"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double A = u[0], B = u[1], eps = p[0], a0 = p[1], a1 = p[2];
    r[0] = A - A * A * A - B;
    r[1] = eps * (A - a1 * B - a0);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double A = u[0], eps = p[0], a1 = p[2];
    J[0] = 1.0 - 3.0 * A * A;
    J[1] = -1.0;
    J[2] = eps;
    J[3] = -eps * a1;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double a0 = p[1], a1 = p[2];
    double A;
    if (a1 == 0.0) {
      A = a0; // the cubic degenerates to A - a0 = 0
    } else {
      // Depressed cubic A^3 + P A + Q = 0.
      const double P = (1.0 - a1) / a1, Q = -a0 / a1;
      const double disc = 0.25 * Q * Q + P * P * P / 27.0;
      if (disc > 0.0) {
        // One real root (Cardano), in the form without cancellation: A = w - P / (3 w).
        const double h = -0.5 * Q;
        const double w = std::cbrt(h + std::copysign(std::sqrt(disc), h));
        A = w - P / (3.0 * w);
      } else if (P < 0.0) {
        // Three real roots m cos(phi/3 - 2 pi j/3), j = 0, 1, 2: largest, middle, smallest.
        const double m = 2.0 * std::sqrt(-P / 3.0);
        const double c = std::fmax(-1.0, std::fmin(1.0, 3.0 * Q / (P * m)));
        const double two_pi = 6.283185307179586;
        A = m * std::cos(std::acos(c) / 3.0 - two_pi / 3.0);
      } else {
        A = 0.0; // P = Q = 0: triple root
      }
      // One Newton step on the original cubic to polish the root.
      const double f = a1 * A * A * A + (1.0 - a1) * A - a0;
      const double df = 3.0 * a1 * A * A + (1.0 - a1);
      if (df != 0.0) A -= f / df;
    }
    u[0] = A;
    u[1] = A - A * A * A;
    return std::isfinite(A);
  }
};

} // namespace morphogen::models
