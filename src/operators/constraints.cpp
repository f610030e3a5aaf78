#include "operators/constraints.hpp"

#include "fields/clamp_floor.hpp"

namespace morphogen {

ClampFloor::ClampFloor(const Grid& grid, std::vector<double> floor)
    : grid_(grid), floor_(std::move(floor)) {}

PetscInt ClampFloor::apply(std::vector<VecH>& u) const {
  return apply_floor(grid_, u, floor_);
}

} // namespace morphogen
