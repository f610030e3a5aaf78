// Turing's model in Turk's form (Sanderson et al. 2006, eqs. 1-4):
//   da/dt = s (a b - a - alpha) + D_a lap a
//   db/dt = s (beta - a b)      + D_b lap b
// alpha is the decay rate of a, beta the growth rate of b, s the reaction rate.
// Homogeneous steady state: a* = beta - alpha, b* = beta / (beta - alpha) (for beta > alpha).
// Turk's and Lawlor's codes clamp negative concentrations to zero; without the clamp the
// Fig. 1 run blows up, so clamping is on by default.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct Turing {
  static constexpr const char* name = "turing";
  static constexpr const char* doc = "Turing's model in Turk's form: spots and stripes";
  static constexpr const char* reference = "Sanderson et al. 2006, eqs. 3-4";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"a", 1.0 / 16.0, 4.0, "activator (consumes b)"},
      {"b", 1.0 / 4.0, 4.0, "substrate"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"alpha", 12.0, 0.0, 1e6, "decay rate of a"},
      {"beta", 16.0, 0.0, 1e6, "growth rate of b"},
      {"s", 1.0 / 128.0, 0.0, 1e6, "reaction rate (scales pattern size)"},
  }};
  static constexpr bool clamp_default = true;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double a = u[0], b = u[1], alpha = p[0], beta = p[1], s = p[2];
    r[0] = s * (a * b - a - alpha);
    r[1] = s * (beta - a * b);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double a = u[0], b = u[1], s = p[2];
    J[0] = s * (b - 1.0);
    J[1] = s * a;
    J[2] = -s * b;
    J[3] = -s * a;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double alpha = p[0], beta = p[1];
    if (!(beta > alpha)) return false;
    u[0] = beta - alpha;
    u[1] = beta / (beta - alpha);
    return true;
  }
};

} // namespace morphogen::models
