// Gray-Scott model in Pearson's form (Sanderson et al. 2006, eqs. 5-6; Pearson 1993):
//   da/dt = s (a^2 b - (F + k) a)  + D_a lap a
//   db/dt = s (-a^2 b + F (1 - b)) + D_b lap b
// a is the autocatalyst (Pearson's v), b the substrate (Pearson's u), F the feed rate, k the
// kill (degradation) rate and s a reaction-rate scale. The trivial homogeneous state a* = 0,
// b* = 1 exists for all parameters and is linearly stable, so patterns only grow from a finite
// perturbation (Pearson seeds a square in the middle of the domain). Pearson's diffusion
// coefficients D_a = 1e-5, D_b = 2e-5 belong to a grid spacing of h = 2.5/256 (about 0.01, as
// Sanderson et al. note in sec. 4); on a unit-spacing grid the same pattern needs D/h^2, i.e.
// D_a of about 0.105 and D_b of about 0.21. Concentrations stay in [0, 1]; no clamping.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

struct GrayScott {
  static constexpr const char* name = "gray_scott";
  static constexpr const char* doc = "Gray-Scott model in Pearson's form: spots, stripes, mitosis";
  static constexpr const char* reference = "Sanderson et al. 2006, eqs. 5-6 (Pearson 1993)";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species{{
      {"a", 1e-5, 0.0, "autocatalyst (Pearson's v)"},
      {"b", 2e-5, 1.0, "substrate (Pearson's u), fed towards 1"},
  }};
  static constexpr std::array<ParamInfo, 3> params{{
      {"F", 0.04, 0.0, 1.0, "feed rate of b"},
      {"k", 0.06, 0.0, 1.0, "kill (degradation) rate of a"},
      {"s", 1.0, 0.0, 1e6, "reaction rate (scales time)"},
  }};
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double a = u[0], b = u[1], F = p[0], k = p[1], s = p[2];
    const double a2b = a * a * b;
    r[0] = s * (a2b - (F + k) * a);
    r[1] = s * (F * (1.0 - b) - a2b);
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double a = u[0], b = u[1], F = p[0], k = p[1], s = p[2];
    J[0] = s * (2.0 * a * b - (F + k));
    J[1] = s * a * a;
    J[2] = -2.0 * s * a * b;
    J[3] = -s * (a * a + F);
  }
  // The trivial state; for F > 4 (F + k)^2 two further homogeneous states exist.
  static inline bool steady_state(const double* /*p*/, double* u) {
    u[0] = 0.0;
    u[1] = 1.0;
    return true;
  }
};

} // namespace morphogen::models
