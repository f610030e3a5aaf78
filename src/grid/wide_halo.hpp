// A wide ghosted copy of a field: the owned box of this rank grown by W cells per axis, filled
// from the owners' cells through one PetscSF (semi-Lagrangian back-traces read up to W cells
// away, further than the grid's stencil width; see operators/advection_stage.hpp).
//
// Along a periodic axis the wide box is the owned range +- W in unwrapped global indices: cell
// i holds the owner's value of cell (i mod n), so W may exceed the neighbours' extent (and even
// n: the images repeat). Along a non-periodic axis the box is clipped to the domain [0, n):
// readers clamp their positions there, so no value outside the domain is ever needed. Roots are
// the owned cells of the grid's ghosted local arrays (owned values only: fresh ghosts of the
// narrow array are not needed). Cell (i,j,k) of the box is at
//   (i - s0) + m0 ((j - s1) + m1 (k - s2)),   x fastest.
#pragma once

#include "grid/grid.hpp"

namespace morphogen {

class WideHalo {
public:
  // width W >= 0 cells beyond the owned box along each of the grid's axes. Collective.
  WideHalo(const Grid& grid, int width);

  int width() const { return width_; }
  const Grid& grid() const { return grid_; }
  // The wide box in global (unwrapped along periodic axes) cell indices.
  const Box& box() const { return box_; }
  PetscInt size() const { return box_.size(); }
  PetscInt index(PetscInt i, PetscInt j, PetscInt k) const {
    return (i - box_.s[0]) + box_.m[0] * ((j - box_.s[1]) + box_.m[1] * (k - box_.s[2]));
  }
  // Fill the wide array w (size()) from the owned cells of the ghosted local arrays `local`
  // of every rank. Collective.
  void fill(const double* local, double* w) const;

private:
  const Grid& grid_;
  int width_;
  Box box_;
  SFH sf_;
};

} // namespace morphogen
