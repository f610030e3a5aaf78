// Constraints applied to the state after each step (and after the split integrator's reaction
// substeps):
//   ClampFloor   u_s <- max(u_s, floor_s) for clamped species (floor_s finite)
//   PinnedCells  u_s <- v_s at the cells of species s's mask (values held fixed; the implicit
//                integrators also take the cells out of their matrices:
//                OperatorMatrices::pin, and the TS right-hand side is zero there)
#pragma once

#include "operators/term.hpp"

namespace morphogen {

class ClampFloor : public Constraint {
public:
  ClampFloor(const Grid& grid, std::vector<double> floor);
  std::string describe() const override { return "clamp floor"; }
  PetscInt apply(std::vector<VecH>& u) const override;
  const std::vector<double>& floor() const { return floor_; }

private:
  const Grid& grid_;
  std::vector<double> floor_;
};

class PinnedCells : public Constraint {
public:
  struct Cell {
    PetscInt local; // ghosted local index
    PetscInt owned; // owned index
    double value;
  };
  // cells[s]: this rank's pinned cells of species s (empty: none).
  PinnedCells(std::vector<std::vector<Cell>> cells, std::vector<std::string> species);
  std::string describe() const override;
  PetscInt apply(std::vector<VecH>& u) const override;
  const std::vector<Cell>& cells(int s) const { return cells_[static_cast<size_t>(s)]; }
  int nspecies() const { return static_cast<int>(cells_.size()); }

private:
  std::vector<std::vector<Cell>> cells_;
  std::vector<std::string> species_;
};

} // namespace morphogen
