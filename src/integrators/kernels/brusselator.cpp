// The Brusselator model's kernels (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template ModelKernels model_kernels<models::Brusselator>();
} // namespace morphogen
