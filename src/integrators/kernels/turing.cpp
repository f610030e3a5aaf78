// The Turing model's kernels (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template ModelKernels model_kernels<models::Turing>();
} // namespace morphogen
