// Reaction model contract.
//
// A model is a struct of static, header-only, pure functions on plain values (no PETSc, MPI,
// allocation, virtual calls or exceptions), so the same code serves the SIMD sweep, the unit
// tests and a future CUDA path. For N species u_0..u_{N-1} and P parameters p_0..p_{P-1}:
//
//   du_s/dt = D_s lap(u_s) + R_s(u; p)
//
// Every model type M provides
//   static constexpr const char* name, *doc, *reference;
//   static constexpr int nspecies, nparams;
//   static constexpr std::array<SpeciesInfo, nspecies> species;   // name, default D, initial value
//   static constexpr std::array<ParamInfo, nparams> params;       // name, default, range, doc
//   static constexpr bool clamp_default;     // clamp negative concentrations to 0 by default
//   static void rates(const double* u, const double* p, double* r);     // r_s = R_s(u; p)
//   static void jacobian(const double* u, const double* p, double* J);  // J[s*N+q] = dR_s/du_q
//   static bool steady_state(const double* p, double* u);  // homogeneous u* with R(u*)=0; false if
//   none
#pragma once

#include "core/host_device.hpp" // MG_HD

#include <array>

namespace morphogen {

struct ParamInfo {
  const char* name;
  double def; // default value
  double lo;  // allowed range, inclusive
  double hi;
  const char* doc;
  const char* def_text = nullptr; // default as an expression (e.g. "x"), overriding def
};

struct SpeciesInfo {
  const char* name;
  double D;    // default diffusion coefficient
  double init; // default initial value (the steady state where the paper starts from it)
  const char* doc;
};

} // namespace morphogen
