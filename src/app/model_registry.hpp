// Registry: model name -> runtime descriptor (species, parameters, kinetics, explicit kernels).
// Built at compile time from the header-only model types in models/all_models.hpp; each entry
// carries the fused explicit row kernel instantiated for every stencil size and for scalar
// or per-cell parameters.
#pragma once

#include "integrators/explicit_kernel.hpp"
#include "integrators/split_integrator.hpp"
#include "models/model.hpp"

#include <string>
#include <vector>

namespace morphogen {

using ExplicitRowFn = void (*)(const ExplicitRow&);

struct ModelEntry {
  const char* name;
  const char* doc;
  const char* reference;
  int nspecies;
  int nparams;
  const SpeciesInfo* species;
  const ParamInfo* params;
  bool clamp_default;
  void (*rates)(const double* u, const double* p, double* r);
  void (*jacobian)(const double* u, const double* p, double* J);
  bool (*steady_state)(const double* p, double* u);
  // explicit_row[field_params][stencil]: stencil 0 = 5pt (3 star rows), 1 = 7pt (5 star rows),
  // 2 = 9pt (3 box rows); see RowStencil.
  ExplicitRowFn explicit_row[2][3];
  // explicit_pre[field_params]: the general explicit path's update (diffusion precomputed).
  ExplicitRowFn explicit_pre[2];
  // reaction_row[field_params]: the per-cell reaction substep of the split integrator.
  ReactionRowFn reaction_row[2];

  // nullptr for a row layout without an instantiated kernel.
  ExplicitRowFn row_kernel(bool field_params, int nrows, bool box) const;
};

const std::vector<ModelEntry>& model_registry();
// nullptr if unknown.
const ModelEntry* find_model(const std::string& name);
std::vector<std::string> model_names();

} // namespace morphogen
