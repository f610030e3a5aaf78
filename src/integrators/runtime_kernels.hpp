// Kernels of a model built at run time (coupled layers, user-defined kinetics): the explicit
// general path's row update and the split integrator's per-cell reaction row, instantiated for
// 1..16 species and up to kMaxRuntimeParams parameters, calling the model's kinetics through
// its callables (ModelInfo::rates, ModelInfo::jacobian; the explicit row uses
// ModelInfo::rates_row, one call per row, when the model has it). Such a model has no fused
// sweep.
#pragma once

#include "integrators/model_kernels.hpp"
#include "models/model_info.hpp"

namespace morphogen {

constexpr int kMaxRuntimeSpecies = 16;
constexpr int kMaxRuntimeParams = 64;

// Throws std::invalid_argument when the model has more species or parameters than the kernels.
ModelKernels runtime_model_kernels(const ModelInfo& model);

} // namespace morphogen
