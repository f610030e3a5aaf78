// Registry: model name -> runtime descriptor (species, parameters, kinetics, explicit kernels).
// Built at compile time from the header-only model types in models/all_models.hpp; each entry
// carries the fused explicit row kernel instantiated for every stencil size and for scalar
// or per-cell parameters.
#pragma once

#include "integrators/explicit_kernel.hpp"
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
  // explicit_row[field_params][stencil]: stencil 0 = 5 terms, 1 = 7 terms, 2 = 9 terms.
  ExplicitRowFn explicit_row[2][3];

  ExplicitRowFn row_kernel(bool field_params, int nterms) const;
};

const std::vector<ModelEntry>& model_registry();
// nullptr if unknown.
const ModelEntry* find_model(const std::string& name);
std::vector<std::string> model_names();

} // namespace morphogen
