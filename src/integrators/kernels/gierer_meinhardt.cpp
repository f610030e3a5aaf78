// The GiererMeinhardt model's explicit rows (see integrators/model_kernels.hpp).
#include "integrators/model_kernels.hpp"

namespace morphogen {
template void explicit_row_kernels<models::GiererMeinhardt, false>(ModelKernels&);
template void explicit_kernels<models::GiererMeinhardt>(ModelKernels&);
} // namespace morphogen
