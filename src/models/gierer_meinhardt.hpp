// Gierer-Meinhardt activator-inhibitor model (Gierer and Meinhardt 1972) in the form of
// Sanderson et al. 2006, eqs. 9-10:
//   da/dt = s (gamma + a^2 / b - alpha a) + D_a lap a
//   db/dt = s (a^2 - beta b)              + D_b lap b
// a is the activator, b the inhibitor, alpha and beta their decay rates, gamma a basal
// production of a. Homogeneous steady state: a* = (gamma + beta) / alpha, b* = a*^2 / beta.
// The paper gives no values, so the defaults are our choice: alpha = 1, beta = 1.5,
// gamma = 0.1, s = 0.5, D_a = 1, D_b = 20. Then (a*, b*) = (1.6, 1.70667); without diffusion
// the state is a stable focus (eigenvalues -0.156 +- 0.592i), and with the default D it is
// Turing-unstable for wavelengths of about 10.7-27 grid units at unit spacing, the fastest
// growing one about 16.5 (growth rate 0.105); a noisy start gives a hexagonal spot pattern.
// (With gamma = 0 a Turing instability needs beta > alpha and D_b / D_a > (1 + sqrt 2)^2
// beta / alpha.) The dynamics keep a, b > 0 for gamma >= 0; b = 0 is a pole, so clamping
// negatives to 0 would not help, and it is off.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct GiererMeinhardt {
  static constexpr const char* name = "gierer_meinhardt";
  static constexpr const char* doc = "Gierer-Meinhardt activator-inhibitor model: spots";
  static constexpr const char* reference = "Sanderson et al. 2006, eqs. 9-10";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 4;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"a", 1.0, 1.6, "activator"},
      {"b", 20.0, 1.6 * 1.6 / 1.5, "inhibitor"},
  }};
  static constexpr std::array<ParamInfo, 4> params{{
      {"alpha", 1.0, 0.0, 1e6, "decay rate of a"},
      {"beta", 1.5, 0.0, 1e6, "decay rate of b"},
      {"gamma", 0.1, 0.0, 1e6, "basal production of a"},
      {"s", 0.5, 0.0, 1e6, "reaction rate (scales pattern size)"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double a = u[0], b = u[1], alpha = p[0], beta = p[1], gamma = p[2], s = p[3];
    const double a2 = a * a;
    r[0] = s * (gamma + a2 / b - alpha * a);
    r[1] = s * (a2 - beta * b);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double a = u[0], b = u[1], alpha = p[0], beta = p[1], s = p[3];
    const double ab = a / b;
    J[0] = s * (2.0 * ab - alpha);
    J[1] = -s * ab * ab;
    J[2] = 2.0 * s * a;
    J[3] = -s * beta;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double alpha = p[0], beta = p[1], gamma = p[2];
    if (!(alpha > 0.0 && beta > 0.0 && gamma + beta > 0.0)) return false;
    const double a = (gamma + beta) / alpha;
    u[0] = a;
    u[1] = a * a / beta;
    return true;
  }
};

} // namespace morphogen::models
