// The Turing model's reaction rows, FMA contraction on (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void reaction_kernels<models::Turing>(ModelKernels&);
} // namespace morphogen
