// Registry: model name -> runtime descriptor (models/model_info.hpp: species, parameters,
// kinetics) plus the model's kernels (integrators/model_kernels.hpp, each model's instantiated
// in its own translation unit).
#pragma once

#include "integrators/model_kernels.hpp"
#include "models/model_info.hpp"

#include <string>
#include <vector>

namespace morphogen {

struct ModelEntry : ModelInfo {
  ModelKernels kernels;
};

const std::vector<ModelEntry>& model_registry();
// nullptr if unknown.
const ModelEntry* find_model(const std::string& name);
std::vector<std::string> model_names();

} // namespace morphogen
