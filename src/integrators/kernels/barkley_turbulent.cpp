// The BarkleyTurbulent model's explicit rows (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void explicit_row_kernels<models::BarkleyTurbulent, false>(ModelKernels&);
template void explicit_kernels<models::BarkleyTurbulent>(ModelKernels&);
} // namespace morphogen
