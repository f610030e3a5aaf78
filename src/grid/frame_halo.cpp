#include "grid/frame_halo.hpp"

#include "core/user_error.hpp"

#include <petscdmda.h>

#include <algorithm>

namespace morphogen {

FrameHalo::FrameHalo(const Grid& grid, int width, Source source) : width_(width) {
  const GridSpec& g = grid.spec();
  if (grid.dim() != 2 || g.bc[0] != Boundary::Periodic || g.bc[1] != Boundary::Periodic ||
      width < 1)
    throw UserError("FrameHalo: needs a 2-D grid periodic on both axes and a width >= 1");
  const Box& ob = grid.owned();
  lx_ = ob.m[0] + 2 * width;
  ly_ = ob.m[1] + 2 * width;
  const auto ax = grid.axis_ranges();
  const PetscInt sw = source == Source::Ghosted ? g.stencil_width : 0; // the owners' arrays
  std::vector<PetscSFNode> remotes;
  auto add = [&](PetscInt i, PetscInt j) { // global (unwrapped) cell of the frame
    const PetscInt c[2] = {(i % g.n[0] + g.n[0]) % g.n[0], (j % g.n[1] + g.n[1]) % g.n[1]};
    const PetscInt p0 = ax[0].owner(c[0]), p1 = ax[1].owner(c[1]);
    const PetscInt gs0 = ax[0].start[p0] - sw, gs1 = ax[1].start[p1] - sw;
    const PetscInt gm0 = ax[0].count[p0] + 2 * sw;
    PetscSFNode r;
    r.rank = p0 + static_cast<PetscInt>(ax[0].start.size()) * p1;
    r.index = (c[0] - gs0) + gm0 * (c[1] - gs1);
    remotes.push_back(r);
  };
  for (PetscInt jw = 0; jw < ly_; ++jw) {
    offset_.push_back(static_cast<PetscInt>(remotes.size()));
    const PetscInt j = ob.s[1] - width + jw, i0 = ob.s[0] - width;
    for (PetscInt iw = 0; iw < lx_; ++iw)
      if (!owned_row(jw) || iw < width || iw >= width + ob.m[0]) add(i0 + iw, j);
  }
  size_ = static_cast<PetscInt>(remotes.size());
  MG_PETSC(PetscSFCreate(grid.comm(), sf_.out()));
  const PetscInt roots = source == Source::Ghosted ? grid.ghosted().size() : grid.owned().size();
  MG_PETSC(PetscSFSetGraph(sf_, roots, size_, nullptr, PETSC_COPY_VALUES, remotes.data(),
                           PETSC_COPY_VALUES));
  MG_PETSC(PetscSFSetUp(sf_));
}

void FrameHalo::fill(const std::vector<const double*>& local, const std::vector<double*>& f) const {
  for (size_t s = 0; s < local.size(); ++s)
    MG_PETSC(PetscSFBcastBegin(sf_, MPIU_SCALAR, local[s], f[s], MPI_REPLACE));
  for (size_t s = 0; s < local.size(); ++s)
    MG_PETSC(PetscSFBcastEnd(sf_, MPIU_SCALAR, local[s], f[s], MPI_REPLACE));
}

} // namespace morphogen
