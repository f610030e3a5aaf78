// Two-variable Oregonator (Tyson-Fife reduction of the Field-Koros-Noyes model of the
// Belousov-Zhabotinsky reaction) in the form of Sanderson et al. 2006, eqs. 27-28:
//   da/dt = (1/eps) (a - a^2 - f b (a - q) / (a + q)) + D_a lap a
//   db/dt = a - b                                     + D_b lap b
// a is the autocatalyst (HBrO2), b the oxidised catalyst; eps the time-scale ratio, f the
// stoichiometric factor, q a small scaled rate constant. Homogeneous steady states: a = b = 0
// (always unstable) and the positive root of a^2 - (1 - q - f) a - q (1 + f) = 0 with b* = a*,
// which steady_state returns (it exists for q > 0, f > -1). Without diffusion that state is
// unstable (relaxation oscillations) for roughly 1/2 < f < 1 + sqrt 2 when q is small, and
// stable outside it (above it the rest state is excitable).
// Defaults: f = 1.4, q = 0.002 (the usual BZ values), eps = 0.02 (our choice among the usual
// 0.01-0.05), D_a = 1 and D_b = 0 (catalyst immobilised, as in gel experiments; also a choice:
// the papers give no values). Then a* = b* = 0.0116053 and the medium oscillates.
// The exact dynamics keep a, b >= 0 (da/dt = f b / eps at a = 0), so clamping negatives to 0
// only removes time-stepping overshoot; it is on by default because it also keeps a away
// from the pole of (a - q) / (a + q) at a = -q.
#pragma once

#include <cmath>

#include "models/model.hpp"

namespace morphogen::models {

struct Oregonator {
  static constexpr const char* name = "oregonator";
  static constexpr const char* doc = "Two-variable Oregonator (BZ reaction): oscillations, spirals";
  static constexpr const char* reference = "Sanderson et al. 2006, eqs. 27-28";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"a", 1.0, 0.011605268043856335, "autocatalyst (HBrO2)"},
      {"b", 0.0, 0.011605268043856335, "oxidised catalyst"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"eps", 0.02, 1e-6, 1e3, "time-scale ratio of a to b (small: stiff)"},
      {"f", 1.4, 0.0, 1e3, "stoichiometric factor"},
      {"q", 0.002, 1e-9, 1.0, "scaled rate-constant ratio"},
  }};
  static constexpr bool clamp_default = true;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double a = u[0], b = u[1], eps = p[0], f = p[1], q = p[2];
    r[0] = (a - a * a - f * b * (a - q) / (a + q)) / eps;
    r[1] = a - b;
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double a = u[0], b = u[1], eps = p[0], f = p[1], q = p[2];
    const double inv = 1.0 / (a + q);
    J[0] = (1.0 - 2.0 * a - 2.0 * f * b * q * inv * inv) / eps;
    J[1] = -f * (a - q) * inv / eps;
    J[2] = 1.0;
    J[3] = -1.0;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double eps = p[0], f = p[1], q = p[2];
    if (!(eps > 0.0 && q > 0.0 && f > -1.0)) return false;
    // a^2 - c a - d = 0 with d > 0: one positive root, computed without cancellation.
    const double c = 1.0 - q - f, d = q * (1.0 + f);
    const double sq = std::sqrt(c * c + 4.0 * d);
    const double a = c >= 0.0 ? 0.5 * (c + sq) : 2.0 * d / (sq - c);
    u[0] = a;
    u[1] = a;
    return true;
  }
};

} // namespace morphogen::models
