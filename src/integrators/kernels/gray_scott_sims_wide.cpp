// The GrayScottSims model's explicit rows compiled with 512-bit vectors (see
// integrators/model_kernels.hpp and CMakeLists.txt): the Wide copies that the explicit integrator
// runs where they are faster.
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void explicit_row_kernels<models::GrayScottSims, true>(ModelKernels&);
} // namespace morphogen
