// Gather one x-y slice (z index k) of a distributed field onto rank `root` (0 unless given),
// for quick-look images and the pattern summary. Each rank sends only its owned rectangle of
// that slice (no rank ever holds the whole 3-D field; the root copies its own cells straight
// into the result: one slice of memory on one rank). Returns nx*ny values (index i + nx*j) on
// the root and an empty vector elsewhere. Collective.
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen::io {

std::vector<double> gather_xy_slice(const Grid& grid, const double* ghosted, PetscInt k,
                                    int root = 0);

} // namespace morphogen::io
