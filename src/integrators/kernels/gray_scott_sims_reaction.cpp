// The GrayScottSims model's reaction rows, FMA contraction on (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void reaction_kernels<models::GrayScottSims>(ModelKernels&);
} // namespace morphogen
