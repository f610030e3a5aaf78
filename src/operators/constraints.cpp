#include "operators/constraints.hpp"

#include "fields/clamp_floor.hpp"

namespace morphogen {

ClampFloor::ClampFloor(const Grid& grid, std::vector<double> floor)
    : grid_(grid), floor_(std::move(floor)) {}

PetscInt ClampFloor::apply(std::vector<VecH>& u) const {
  return apply_floor(grid_, u, floor_);
}

PinnedCells::PinnedCells(std::vector<std::vector<Cell>> cells, std::vector<std::string> species)
    : cells_(std::move(cells)), species_(std::move(species)) {}

std::string PinnedCells::describe() const {
  std::string names;
  for (size_t s = 0; s < species_.size(); ++s)
    names += (names.empty() ? "" : ", ") + species_[s];
  return "pinned cells (" + names + ")";
}

PetscInt PinnedCells::apply(std::vector<VecH>& u) const {
  PetscInt changed = 0;
  for (size_t s = 0; s < cells_.size(); ++s) {
    if (cells_[s].empty()) continue;
    PetscScalar* a = nullptr;
    MG_PETSC(VecGetArray(u[s], &a));
    for (const Cell& c : cells_[s]) {
      changed += a[c.local] != c.value;
      a[c.local] = c.value;
    }
    MG_PETSC(VecRestoreArray(u[s], &a));
  }
  return changed;
}

} // namespace morphogen
