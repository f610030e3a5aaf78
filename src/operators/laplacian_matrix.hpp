// The discrete Laplacian with the boundary conditions folded in, as a PETSc matrix on the
// DMDA (global layout), plus a constant vector per species for Dirichlet data:
//
//   (L u + b_s)_c = sum_t w_t u(c + off_t)   with the ghost rules of Halo::fill_boundaries:
//   outside a zero-flux face u_ghost = u_mirror (the weight moves onto the mirror cell), outside
//   a Dirichlet face u_ghost = 2 g - u_mirror (the weight moves with a minus sign, 2 g w goes
//   into b_s); periodic neighbours wrap. So L u + b equals the explicit scheme's Laplacian.
// Used by the implicit diffusion substep and by the TS integrator's implicit part.
#pragma once

#include "grid/halo.hpp"
#include "grid/stencil.hpp"

#include <functional>
#include <petscmat.h>
#include <vector>

namespace morphogen {

class LaplacianMatrix {
public:
  // One stencil term of a cell: neighbour offset and weight.
  struct CellTerm {
    int off[3];
    double w;
  };
  // Terms of owned cell (i, j, k) (appended to `out`, which arrives empty).
  using CellTermsFn = std::function<void(PetscInt, PetscInt, PetscInt, std::vector<CellTerm>&)>;

  LaplacianMatrix(const Grid& grid, const Halo& halo, const Stencil& stencil, int nspecies,
                  const std::vector<FaceValues>* dirichlet);
  // A variable stencil (a diffusion operator's weights per cell); b for the nspecies Dirichlet
  // value sets in `dirichlet` (may be null).
  LaplacianMatrix(const Grid& grid, const Halo& halo, const CellTermsFn& terms, int nspecies,
                  const std::vector<FaceValues>* dirichlet);
  LaplacianMatrix(const LaplacianMatrix&) = delete;
  LaplacianMatrix& operator=(const LaplacianMatrix&) = delete;

  Mat L() const { return L_.get(); }
  Vec b(int species) const { return b_[species]; }
  // New Dirichlet values (one set per species, as at construction): b is recomputed in place
  // (the same Vecs), L is kept. Collective.
  void set_dirichlet(const std::vector<FaceValues>& dirichlet);

private:
  // matrix false: only b (L exists already).
  void assemble(const std::vector<FaceValues>* dirichlet, bool matrix);

  const Grid& grid_;
  const Halo& halo_;
  CellTermsFn terms_;
  int nspecies_;
  MatH L_;
  std::vector<VecH> b_;
};

} // namespace morphogen
