// Barkley's model of excitable media (Barkley 1991) as given in Appendix A of "Stable
// Advection-Reaction-Diffusion with Arbitrary Anisotropy":
//   dA/dt = (1/eps) A (1 - A) (A - (B + b) / a) + D_A lap A
//   dB/dt = A - B                                (+ D_B lap B, D_B = 0 by default)
// A is the fast excitation variable, B the slow recovery variable; (B + b) / a is the
// excitation threshold. The appendix writes the threshold as (V + b) / a; V is B.
// The rest state A* = B* = 0 is a homogeneous steady state for all parameters (a, eps > 0);
// it is excitable, so waves need a supra-threshold seed (a broken plane wave gives a spiral).
// Defaults a = 0.75, b = 0.02, eps = 0.02: a broken plane wave curls into a steady spiral.
//
// Barkley's "turbulent" variant (same appendix) replaces the recovery kinetics by
//   dB/dt = A^3 - B,
// which delays recovery and lets spirals break up into spatiotemporal chaos. Its defaults
// differ (our choice): a = 0.75, b = 0.06, eps = 0.08; we checked that a broken wave there
// becomes a spiral whose core breaks up into turbulence that fills the domain, while with
// the regular model's defaults the variant only gives a stable, tightly wound spiral.
#pragma once

#include "models/model.hpp"

namespace morphogen::models {

namespace detail {
// R_A and its partial derivatives, shared by both Barkley variants. p = {a, b, eps}.
MG_HD inline double barkley_ra(double A, double B, const double* p) {
  const double a = p[0], b = p[1], eps = p[2];
  return A * (1.0 - A) * (A - (B + b) / a) / eps;
}
MG_HD inline void barkley_dra(double A, double B, const double* p, double* J) {
  const double a = p[0], b = p[1], eps = p[2];
  const double th = (B + b) / a;
  J[0] = ((1.0 - 2.0 * A) * (A - th) + A * (1.0 - A)) / eps;
  J[1] = -A * (1.0 - A) / (a * eps);
}
constexpr std::array<SpeciesInfo, 2> barkley_species{{
    {"A", 1.0, 0.0, "fast excitation variable"},
    {"B", 0.0, 0.0, "slow recovery variable (does not diffuse)"},
}};
constexpr std::array<ParamInfo, 3> barkley_params(double b, double eps) {
  return {{
      {"a", 0.75, 1e-6, 1e3, "threshold scale: threshold is (B + b) / a"},
      {"b", b, 0.0, 1e3, "threshold offset (excitability)"},
      {"eps", eps, 1e-6, 1e3, "time-scale ratio of A to B (small: stiff, sharp fronts)"},
  }};
}
inline bool barkley_steady_state(const double* p, double* u) {
  if (!(p[0] > 0.0 && p[2] > 0.0)) return false;
  u[0] = 0.0;
  u[1] = 0.0;
  return true;
}
} // namespace detail

struct Barkley {
  static constexpr const char* name = "barkley";
  static constexpr const char* doc = "Barkley's excitable medium: spiral waves";
  static constexpr const char* reference =
      "Stable advection-reaction-diffusion with arbitrary anisotropy, Appendix A (Barkley 1991)";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species = detail::barkley_species;
  static constexpr std::array<ParamInfo, 3> params = detail::barkley_params(0.02, 0.02);
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double A = u[0], B = u[1];
    r[0] = detail::barkley_ra(A, B, p);
    r[1] = A - B;
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    detail::barkley_dra(u[0], u[1], p, J);
    J[2] = 1.0;
    J[3] = -1.0;
  }
  static inline bool steady_state(const double* p, double* u) {
    return detail::barkley_steady_state(p, u);
  }
};

struct BarkleyTurbulent {
  static constexpr const char* name = "barkley_turbulent";
  static constexpr const char* doc = "Barkley's model with dB/dt = A^3 - B: spiral breakup";
  static constexpr const char* reference =
      "Stable advection-reaction-diffusion with arbitrary anisotropy, Appendix A (Barkley 1991)";
  static constexpr int nspecies = 2;
  static constexpr int nparams = 3;
  static constexpr std::array<SpeciesInfo, 2> species = detail::barkley_species;
  static constexpr std::array<ParamInfo, 3> params = detail::barkley_params(0.06, 0.08);
  static constexpr bool clamp_default = false;

  MG_HD static inline void rates(const double* u, const double* p, double* r) {
    const double A = u[0], B = u[1];
    r[0] = detail::barkley_ra(A, B, p);
    r[1] = A * A * A - B;
  }
  MG_HD static inline void jacobian(const double* u, const double* p, double* J) {
    const double A = u[0];
    detail::barkley_dra(A, u[1], p, J);
    J[2] = 3.0 * A * A;
    J[3] = -1.0;
  }
  static inline bool steady_state(const double* p, double* u) {
    return detail::barkley_steady_state(p, u);
  }
};

} // namespace morphogen::models
