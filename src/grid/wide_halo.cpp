#include "grid/wide_halo.hpp"

#include <petscdmda.h>

#include <algorithm>

namespace morphogen {

namespace {

// The wide box: owned +- width, clipped to [0, n) along non-periodic axes.
Box wide_box(const Grid& grid, int width) {
  const GridSpec& g = grid.spec();
  Box b = grid.owned();
  for (int d = 0; d < grid.dim(); ++d) {
    PetscInt lo = b.s[d] - width, hi = b.s[d] + b.m[d] + width;
    if (g.bc[d] != Boundary::Periodic) {
      lo = std::max<PetscInt>(lo, 0);
      hi = std::min<PetscInt>(hi, g.n[d]);
    }
    b.s[d] = lo;
    b.m[d] = hi - lo;
  }
  return b;
}

} // namespace

WideHalo::WideHalo(const Grid& grid, int width)
    : grid_(grid), width_(width), box_(wide_box(grid, width)) {
  const GridSpec& g = grid.spec();
  const auto ax = grid.axis_ranges();
  const int sw = g.stencil_width; // the owners' ghosted local arrays
  std::vector<PetscSFNode> remotes;
  remotes.reserve(static_cast<size_t>(box_.size()));
  for (PetscInt k = box_.s[2]; k < box_.s[2] + box_.m[2]; ++k)
    for (PetscInt j = box_.s[1]; j < box_.s[1] + box_.m[1]; ++j)
      for (PetscInt i = box_.s[0]; i < box_.s[0] + box_.m[0]; ++i) {
        PetscInt c[3] = {i, j, k}, p[3], gs[3], gm[3];
        for (int d = 0; d < 3; ++d) {
          c[d] = (c[d] % g.n[d] + g.n[d]) % g.n[d]; // only periodic axes leave [0, n)
          p[d] = ax[d].owner(c[d]);
          const PetscInt ghost = d < grid.dim() ? sw : 0;
          gs[d] = ax[d].start[p[d]] - ghost;
          gm[d] = ax[d].count[p[d]] + 2 * ghost;
        }
        PetscSFNode r;
        r.rank = p[0] + static_cast<PetscInt>(ax[0].start.size()) *
                            (p[1] + static_cast<PetscInt>(ax[1].start.size()) * p[2]);
        r.index = (c[0] - gs[0]) + gm[0] * ((c[1] - gs[1]) + gm[1] * (c[2] - gs[2]));
        remotes.push_back(r);
      }
  MG_PETSC(PetscSFCreate(grid.comm(), sf_.out()));
  MG_PETSC(PetscSFSetGraph(sf_, grid.ghosted().size(), box_.size(), nullptr, PETSC_COPY_VALUES,
                           remotes.data(), PETSC_COPY_VALUES));
  MG_PETSC(PetscSFSetUp(sf_));
}

void WideHalo::fill(const double* local, double* w) const {
  MG_PETSC(PetscSFBcastBegin(sf_, MPIU_SCALAR, local, w, MPI_REPLACE));
  MG_PETSC(PetscSFBcastEnd(sf_, MPIU_SCALAR, local, w, MPI_REPLACE));
}

} // namespace morphogen
