// Schnakenberg's activator-substrate model (Schnakenberg 1979; Murray, Mathematical Biology):
//   du/dt = gamma (a - u + u^2 v) + D_u lap u
//   dv/dt = gamma (b - u^2 v)     + D_v lap v
// u is the activator, v the substrate; a and b are the supply rates, gamma the reaction rate.
// Homogeneous steady state: u* = a + b, v* = b / (a + b)^2.
// Defaults a = 0.1, b = 0.9, gamma = 1 (the classic values) give (u*, v*) = (1, 0.9), stable
// without diffusion (eigenvalues -0.1 +- 0.995i). Turing instability needs D_v / D_u > 8.57;
// we choose D_u = 1, D_v = 20, for which the fastest-growing wavelength is about 12.9 grid
// units at unit spacing (growth rate 0.26); a noisy start gives spots of u.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct Schnakenberg {
  static constexpr const char* name = "schnakenberg";
  static constexpr const char* doc = "Schnakenberg activator-substrate model: spots and stripes";
  static constexpr const char* reference = "Schnakenberg 1979 (J. Theor. Biol. 81:389)";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"u", 1.0, 1.0, "activator"},
      {"v", 20.0, 0.9, "substrate (consumed by u)"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"a", 0.1, 0.0, 1e6, "supply rate of u"},
      {"b", 0.9, 0.0, 1e6, "supply rate of v"},
      {"gamma", 1.0, 0.0, 1e6, "reaction rate (scales pattern size)"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double U = u[0], V = u[1], a = p[0], b = p[1], gamma = p[2];
    const double u2v = U * U * V;
    r[0] = gamma * (a - U + u2v);
    r[1] = gamma * (b - u2v);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double U = u[0], V = u[1], gamma = p[2];
    J[0] = gamma * (2.0 * U * V - 1.0);
    J[1] = gamma * U * U;
    J[2] = -2.0 * gamma * U * V;
    J[3] = -gamma * U * U;
  }
  static inline bool steady_state(const double* p, double* u) {
    const double a = p[0], b = p[1];
    const double ab = a + b;
    if (!(ab > 0.0)) return false;
    u[0] = ab;
    u[1] = b / (ab * ab);
    return true;
  }
};

} // namespace morphogen::models
