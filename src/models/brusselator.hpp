// Brusselator (Prigogine and Lefever 1968) in the form of Sanderson et al. 2006, eqs. 7-8:
//   da/dt = s (alpha - (1 + beta) a + a^2 b) + D_a lap a
//   db/dt = s (beta a - a^2 b)               + D_b lap b
// Homogeneous steady state: a* = alpha, b* = beta / alpha (alpha > 0). Without diffusion it
// is stable for beta < 1 + alpha^2 (Hopf bifurcation at beta = 1 + alpha^2).
// Defaults are the second layer of Sanderson et al.'s Table 1 (Figs. 10, 18): alpha = 3,
// beta = 9, s = 1, D_a = 49.4, D_b = 117.6, starting from the steady state (3, 3). With these
// D the steady state is (just) Turing-unstable, fastest-growing wavelength about 31.5 grid
// units at unit spacing. (The table's first layer, D = 16.7 / 36.4, is Turing-stable alone.)
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct Brusselator {
  static constexpr const char* name = "brusselator";
  static constexpr const char* doc =
      "Brusselator: depletion model, spots (double spots when coupled)";
  static constexpr const char* reference = "Sanderson et al. 2006, eqs. 7-8";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"a", 49.4, 3.0, "activator"},
      {"b", 117.6, 3.0, "substrate (depleted by a)"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"alpha", 3.0, 0.0, 1e6, "supply rate of a (steady a* = alpha)"},
      {"beta", 9.0, 0.0, 1e6, "conversion rate of a into b"},
      {"s", 1.0, 0.0, 1e6, "reaction rate (scales pattern size)"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double a = u[0], b = u[1], alpha = p[0], beta = p[1], s = p[2];
    const double a2b = a * a * b;
    r[0] = s * (alpha - (1.0 + beta) * a + a2b);
    r[1] = s * (beta * a - a2b);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double a = u[0], b = u[1], beta = p[1], s = p[2];
    J[0] = s * (2.0 * a * b - (1.0 + beta));
    J[1] = s * a * a;
    J[2] = s * (beta - 2.0 * a * b);
    J[3] = -s * a * a;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double alpha = p[0], beta = p[1];
    if (!(alpha > 0.0)) return false;
    u[0] = alpha;
    u[1] = beta / alpha;
    return true;
  }
};

} // namespace morphogen::models
