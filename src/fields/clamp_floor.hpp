// Clamp of negative concentrations: u_s <- max(u_s, floor_s) on the owned cells of ghosted
// local state vectors (floor_s = 0 when clamping, -inf otherwise: such species are skipped).
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen {

// Returns the number of owned values this rank changed.
PetscInt apply_floor(const Grid& grid, std::vector<VecH>& u, const std::vector<double>& floor);

} // namespace morphogen
