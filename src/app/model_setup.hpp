// The run's model from the options:
//   -model NAME     a registered model (app/model_registry.hpp), or `custom`
//   -layers L       L >= 2 coupled copies of the model (models/runtime_model.hpp: species a1,
//                   b1, a2, ..., parameters alpha1, ..., coupling rates couple_<species>)
//   -species LIST   (custom) the species names, e.g. a,b
//   -rate_S EXPR    (custom) the rate of species S, an expression of the species and of
//                   parameters, each given with -params_NAME
//   -jac_S_Q EXPR   (custom, optional) dR_S/dQ for the implicit paths: all entries or none
//                   (none: central differences)
#pragma once

#include "app/model_registry.hpp"
#include "core/options.hpp"

#include <memory>

namespace morphogen {

// A registered model's entry (not owned) or a model built at run time (owned).
std::shared_ptr<const ModelEntry> read_model_choice(Options& opt);

// "custom" and the registered names (the allowed values of -model).
std::vector<std::string> model_choices();

} // namespace morphogen
