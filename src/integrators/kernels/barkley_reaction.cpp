// The Barkley model's reaction rows, FMA contraction on (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void reaction_kernels<models::Barkley>(ModelKernels&);
} // namespace morphogen
