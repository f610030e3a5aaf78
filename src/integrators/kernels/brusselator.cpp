// The Brusselator model's explicit rows (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void explicit_row_kernels<models::Brusselator, false>(ModelKernels&);
template void explicit_kernels<models::Brusselator>(ModelKernels&);
} // namespace morphogen
