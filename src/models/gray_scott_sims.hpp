// Gray-Scott model in Karl Sims' form, as used by Garrity ("How the Tiger got its Stripes"):
//   dA/dt = D_A lap A - A B^2 + f (1 - A)
//   dB/dt = D_B lap B + A B^2 - (k + f) B
// A is the substrate (fed towards 1 at rate f), B the autocatalyst (removed at rate k + f).
// This is Pearson's form (gray_scott) with the roles written A = Pearson's u, B = Pearson's v.
// Homogeneous steady state A* = 1, B* = 0 (linearly stable: seed a patch of B, as Garrity does).
// Garrity's presets: f/k = .055/.062 (default), .018/.051, .026/.053, .055/.063.
// Note on D: Garrity's 9-point stencil (weights -1, 0.2 edges, 0.05 corners) is 0.3 times the
// standard 9-point Laplacian at unit spacing, so his D_A = 1, D_B = 0.5 correspond to 0.3 and
// 0.15 with a consistent unit-spacing Laplacian (or keep D and use spacing h = 1/sqrt(0.3)).
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct GrayScottSims {
  static constexpr const char* name = "gray_scott_sims";
  static constexpr const char* doc = "Gray-Scott model in Karl Sims' form (feed f, kill k)";
  static constexpr const char* reference = "Garrity, How the Tiger got its Stripes (after K. Sims)";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 2;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"A", 1.0, 1.0, "substrate, fed towards 1"},
      {"B", 0.5, 0.0, "autocatalyst"},
  }};
  static constexpr std::array<ParamInfo, 2> params{{
      {"f", 0.055, 0.0, 1.0, "feed rate of A"},
      {"k", 0.062, 0.0, 1.0, "kill rate of B"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double A = u[0], B = u[1], f = p[0], k = p[1];
    const double ab2 = A * B * B;
    r[0] = f * (1.0 - A) - ab2;
    r[1] = ab2 - (k + f) * B;
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double A = u[0], B = u[1], f = p[0], k = p[1];
    J[0] = -B * B - f;
    J[1] = -2.0 * A * B;
    J[2] = B * B;
    J[3] = 2.0 * A * B - (k + f);
  }
  // The trivial state; for f > 4 (f + k)^2 two further homogeneous states exist.
  static inline bool steady_state(const double* /*p*/, double* u) {
    u[0] = 1.0;
    u[1] = 0.0;
    return true;
  }
};

} // namespace morphogen::models
