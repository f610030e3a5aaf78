#include "operators/laplacian_matrix.hpp"

#include <petscdmda.h>

#include <algorithm>

namespace morphogen {

namespace {

// A neighbour value as a linear combination of cells of the ghosted box (periodic positions
// unwrapped) plus constants.
struct Term {
  PetscInt c[3];
  double coef;
};

} // namespace

LaplacianMatrix::LaplacianMatrix(const Grid& grid, const Halo& halo, const Stencil& stencil,
                                 int nspecies, const std::vector<FaceValues>* dirichlet)
    : grid_(grid), halo_(halo),
      terms_([stencil](PetscInt, PetscInt, PetscInt, std::vector<CellTerm>& out) {
        for (int t = 0; t < stencil.nterms; ++t)
          out.push_back({{stencil.off[t][0], stencil.off[t][1], stencil.off[t][2]}, stencil.w[t]});
      }),
      nspecies_(nspecies) {
  assemble(dirichlet, true);
}

LaplacianMatrix::LaplacianMatrix(const Grid& grid, const Halo& halo, const CellTermsFn& terms,
                                 int nspecies, const std::vector<FaceValues>* dirichlet)
    : grid_(grid), halo_(halo), terms_(terms), nspecies_(nspecies) {
  assemble(dirichlet, true);
}

void LaplacianMatrix::set_dirichlet(const std::vector<FaceValues>& dirichlet) {
  assemble(&dirichlet, false);
}

void LaplacianMatrix::assemble(const std::vector<FaceValues>* dirichlet, bool matrix) {
  const Grid& grid = grid_;
  const Halo& halo = halo_;
  const CellTermsFn& cell_terms = terms_;
  const GridSpec& g = grid.spec();
  const size_t ns = static_cast<size_t>(nspecies_);
  if (matrix) {
    DM dm = grid.dm();
    MG_PETSC(DMSetMatType(dm, MATAIJ));
    MG_PETSC(DMCreateMatrix(dm, L_.out()));
    // Preallocated for the DMDA's stencil (box when any operator has cross terms): a term
    // outside it is a bug, reported instead of silently reallocating.
    MG_PETSC(MatSetOption(L_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
    for (size_t s = 0; s < ns; ++s)
      b_.push_back(grid.create_global());
  }
  std::vector<PetscScalar*> barr(ns);
  for (size_t s = 0; s < ns; ++s)
    MG_PETSC(VecGetArray(b_[s], &barr[s]));
  const Box& ob = grid.owned();
  // Resolve a stencil neighbour q (global indices, possibly outside the domain) into in-domain
  // cells; Dirichlet constants (2 g per species) accumulate into consts with sign `sign`.
  std::vector<double> consts(ns);
  std::vector<Term> terms;
  // q is unwrapped (a position in this rank's ghosted box); as in Halo::fill_boundaries, the
  // highest non-periodic axis on which q is outside decides, recursively.
  auto resolve = [&](auto&& self, PetscInt qi, PetscInt qj, PetscInt qk, double coef) -> void {
    const PetscInt q[3] = {qi, qj, qk};
    int dd = -1;
    for (int d = 0; d < grid.dim(); ++d)
      if (g.bc[d] != Boundary::Periodic && (q[d] < 0 || q[d] >= g.n[d])) dd = d;
    if (dd < 0) {
      // Periodic coordinates stay unwrapped: MatSetValuesStencil maps ghost positions of
      // this rank's ghosted box through the DMDA's periodic numbering.
      terms.push_back({{q[0], q[1], q[2]}, coef});
      return;
    }
    const int side = q[dd] < 0 ? 0 : 1;
    PetscInt m[3] = {q[0], q[1], q[2]};
    m[dd] = side == 0 ? -q[dd] - 1 : 2 * g.n[dd] - 1 - q[dd];
    if (g.bc[dd] == Boundary::Dirichlet) {
      for (size_t s = 0; s < ns; ++s)
        consts[s] +=
            coef * 2.0 * (*dirichlet)[s].face[2 * dd + side][halo.face_index(dd, q[0], q[1], q[2])];
      self(self, m[0], m[1], m[2], -coef);
    } else {
      self(self, m[0], m[1], m[2], coef);
    }
  };
  std::vector<MatStencil> cols;
  std::vector<PetscScalar> vals;
  std::vector<CellTerm> cterms;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        terms.clear();
        std::fill(consts.begin(), consts.end(), 0.0);
        cterms.clear();
        cell_terms(i, j, k, cterms);
        for (const CellTerm& ct : cterms)
          resolve(resolve, i + ct.off[0], j + ct.off[1], k + ct.off[2], ct.w);
        for (size_t s = 0; s < ns; ++s)
          barr[s][grid.owned_index(i, j, k)] = consts[s];
        if (!matrix) continue;
        MatStencil row{};
        row.i = i, row.j = j, row.k = k;
        cols.clear();
        vals.clear();
        for (const Term& tm : terms) {
          MatStencil c{};
          c.i = tm.c[0], c.j = tm.c[1], c.k = tm.c[2];
          cols.push_back(c);
          vals.push_back(tm.coef);
        }
        MG_PETSC(MatSetValuesStencil(L_, 1, &row, static_cast<PetscInt>(cols.size()), cols.data(),
                                     vals.data(), ADD_VALUES));
      }
  if (matrix) {
    MG_PETSC(MatAssemblyBegin(L_, MAT_FINAL_ASSEMBLY));
    MG_PETSC(MatAssemblyEnd(L_, MAT_FINAL_ASSEMBLY));
  }
  for (size_t s = 0; s < ns; ++s)
    MG_PETSC(VecRestoreArray(b_[s], &barr[s]));
}

} // namespace morphogen
