// Halo update of a ghosted local array, in place, without copying owned values.
//
// Ghost cells whose (periodically wrapped) position lies inside the domain are received from
// their owner through one PetscSF whose roots and leaves are both positions in the ghosted local
// arrays (halo-only: no global-to-local copy of the interior); on one rank by direct copies. Ghost
// cells outside a non-periodic boundary are then filled axis by axis (x, then y, then z, so
// box-stencil corners come out right), for the cell-centred grid:
//   zero flux (Neumann):  u_ghost = u_inside                 (du/dn = 0 at the face)
//   Dirichlet value g:    u_ghost = 2 g - u_inside           (u = g at the face, 2nd order)
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen {

// Dirichlet values of one field on the six faces (lo/hi per axis). face[2*d + side] is indexed
// over the ghosted box of the other two axes, x fastest (see Halo::face_index).
struct FaceValues {
  std::array<std::vector<double>, 6> face;
};

class Halo {
public:
  // x_wrap = false leaves out every ghost outside the domain in x (the periodic x wrap and the
  // corners beyond it), for a caller that fills the x ghosts it reads itself (the explicit
  // sweep of a star stencil: integrators/explicit_integrator.hpp).
  explicit Halo(const Grid& grid, bool x_wrap = true);

  // Start / finish the exchange of inter-rank and periodic ghosts of `a` (ghosted local array).
  void begin(double* a) const;
  void end(double* a) const;
  // Fill ghosts outside non-periodic boundaries (after end()). `dirichlet` may be null when no
  // axis is Dirichlet. With stride n the field is one component of an interlaced local array
  // (cell c at a[n * c]: a DMDA with n dof and this grid's layout).
  void fill_boundaries(double* a, const FaceValues* dirichlet, PetscInt stride = 1) const;
  // Fill ghosts outside non-periodic boundaries with the mirror value times sign[d] for the
  // face normal to axis d, whatever the boundary type (coefficient fields: a tensor's
  // off-diagonal component changes sign under a reflection, so its mirror image is odd).
  void fill_mirror(double* a, const std::array<double, 3>& sign) const;
  // The whole update: begin, end, fill_boundaries.
  void update(double* a, const FaceValues* dirichlet) const {
    begin(a);
    end(a);
    fill_boundaries(a, dirichlet);
  }

  // Position (in the face array of axis d) of ghosted-box cell (i,j,k): the other two axes'
  // offsets.
  PetscInt face_index(int d, PetscInt i, PetscInt j, PetscInt k) const;
  PetscInt face_size(int d) const;

private:
  void fill_faces(double* a, const FaceValues* dirichlet, const std::array<double, 3>& sign,
                  PetscInt stride) const;

  const Grid& grid_;
  SFH sf_;
  // On a one-rank communicator (a sweep point, a serial run) the periodic ghosts are copied
  // directly, without PetscSF's pack/unpack and call overhead (a quarter of a 64^2 explicit
  // step): runs of at least kMinRun consecutive ghosts with consecutive sources (whole ghost
  // rows) as block copies; of the others, runs of at least kMinRun ghosts a fixed stride apart
  // with their sources the same stride apart (ghost columns: the stride is a row) as strided
  // copies, with no index loads; the rest one by one, ghost_[q] <- source_[q].
  struct Run {
    PetscInt ghost, source, len, stride;
  };
  static constexpr PetscInt kMinRun = 8;
  void split_runs(const std::vector<PetscInt>& ghost, const std::vector<PetscInt>& source);
  void split_strided(std::vector<PetscInt> ghost, std::vector<PetscInt> source);
  bool local_only_ = false;
  std::vector<Run> runs_, strided_;
  std::vector<PetscInt> ghost_, source_;
};

} // namespace morphogen
