// Constraints applied to the state after each step (and after the split integrator's reaction
// substeps):
//   ClampFloor  u_s <- max(u_s, floor_s) for clamped species (floor_s finite)
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

} // namespace morphogen
