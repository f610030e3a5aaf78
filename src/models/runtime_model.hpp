// Models built at run time from a description rather than a compiled model type:
//   layered_model  L coupled copies of a registered model (Sanderson et al. 2006, eqs. 20-21)
//   custom_model   user-defined kinetics, one muParser expression per species
// Both return a ModelInfo whose names and kinetics live in ModelInfo::storage (shared, so
// copies stay valid). Their kinetics are callables, not compiled kernels: the explicit
// integrator takes its general path and the split integrator its generic per-cell Newton.
#pragma once

#include "models/model_info.hpp"

#include <string>
#include <vector>

namespace morphogen {

// The most species of a custom model and of the base model of layers: their Jacobians work in
// fixed stack buffers of this size (no allocation per call; the split integrator's per-cell
// Newton calls them per cell and iteration). The runtime kernels' limit (kMaxRuntimeSpecies).
constexpr int kMaxModelSpecies = 16;

// Coupled layers: layer l = 1..L of `base` has species <s><l> (a1, b1, a2, b2, ...) and
// parameters <p><l> (alpha1, beta1, ...); then one coupling rate couple_<s> per base species
// (default 0, a parameter like any other: constant, a field, or a function of t):
//   du_{s,l}/dt = R_s(u_l; p_l) + couple_s * sum_{m = l-1, l+1 in 1..L} (u_{s,m} - u_{s,l})
// For L = 2 this is eqs. 20-21 (mu = couple_a, nu = couple_b). The Jacobian is the layers'
// blocks plus the coupling. Steady state: the layers' own, when they agree on every coupled
// species (otherwise none is claimed). Throws UserError when L is out of 2..16, names clash or
// the base model has more than kMaxModelSpecies species.
ModelInfo layered_model(const ModelInfo& base, int layers);

// User-defined kinetics: R_s = rates[s], a muParser expression of the species and of any other
// name, which becomes a parameter (parameters in alphabetical order); x, y, z and t are
// parameters whose default is that expression. keys[s] names the option of
// rates[s] in messages (e.g. "-rate_a"). Jacobian: jac[s * ns + q] = dR_s/du_q, expressions
// like the rates (names in them that are not species are parameters too), all ns^2 entries or
// none (then central differences); jac_keys[e] names the option of jac[e] (e.g. "-jac_a_b").
// No steady state is claimed (the analysis searches for one). Throws UserError on a bad name
// or expression, more than kMaxModelSpecies species, or a partial Jacobian.
struct CustomKinetics {
  std::vector<std::string> species;
  std::vector<std::string> rates;
  std::vector<std::string> keys;
  std::vector<std::string> jac = {}, jac_keys = {};
};
ModelInfo custom_model(const CustomKinetics& spec);
// The species names of spec (UserError unless each is an identifier other than x, y, z, t, pi,
// named once even ignoring case, as PETSc's option names -rate_<s> and -D_<s> do, and there are
// at most kMaxModelSpecies); custom_model checks them first too.
void check_species(const CustomKinetics& spec);

} // namespace morphogen
