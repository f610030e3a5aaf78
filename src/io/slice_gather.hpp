// Gather one x-y slice (z index k) of a distributed field onto rank 0, for quick-look images.
// Each rank sends only its owned rectangle of that slice (no rank ever holds the whole 3-D
// field; rank 0 copies its own cells straight into the result: one slice of memory on one
// rank). Returns nx*ny values (index i + nx*j) on rank 0 and an empty vector elsewhere.
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen::io {

std::vector<double> gather_xy_slice(const Grid& grid, const double* ghosted, PetscInt k);

} // namespace morphogen::io
