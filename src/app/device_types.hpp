// -dm_vec_type / -dm_mat_type: the vector and matrix types of the grid. This build computes on
// the host (Debian's PETSc has no CUDA): host types are accepted, device types (cuda,
// aijcusparse, kokkos, hip, ...) are a one-line error that says how to get a GPU-enabled build.
#pragma once

#include "core/options.hpp"

namespace morphogen {

void read_device_types(Options& opt);

} // namespace morphogen
