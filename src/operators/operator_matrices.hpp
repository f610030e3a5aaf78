// The diffusion operators of all species as matrices with the boundary conditions folded in:
//
//   (K_s u)_c = scale_s ((M_s u)_c + b_s,c)
//
// equals the explicit operator (DiffusionOperator::apply_row on a halo-filled state). Species
// with constant isotropic diffusion share one matrix, the run's Laplacian stencil, with
// scale_s = D_s (so today's matrices and their round-off are kept); every other species has its
// own matrix with the coefficients folded in (scale_s = 1). Used by the implicit diffusion
// substep and by the TS integrator's implicit part.
#pragma once

#include "operators/diffusion_operator.hpp"
#include "operators/laplacian_matrix.hpp"

#include <memory>
#include <vector>

namespace morphogen {

class OperatorMatrices {
public:
  // ops: one per species; dirichlet: one value set per species, or null.
  OperatorMatrices(const Grid& grid, const Halo& halo, const Stencil& stencil,
                   const std::vector<const DiffusionOperator*>& ops,
                   const std::vector<FaceValues>* dirichlet);

  int nspecies() const { return static_cast<int>(scale_.size()); }
  Mat M(int s) const { return pinned_M_[s] ? pinned_M_[s].get() : mat_[s]->L(); }
  Vec b(int s) const { return pinned_b_[s] ? pinned_b_[s].get() : mat_[s]->b(index_[s]); }
  // Hold species s at `values` on the cells `rows` (this rank's, in the DMDA's global
  // numbering): rows and columns of M_s are zeroed (the matrix stays symmetric) and the
  // coupling to the held values moves into b_s, whose pinned rows are 0, so K_s u = 0 there.
  // Collective.
  void pin(int s, const std::vector<PetscInt>& rows, const std::vector<double>& values);
  // Re-assemble species s's own matrix from its operator (whose coefficients changed:
  // solution-dependent diffusion, lagged), pinned cells held again. Collective.
  void reassemble(int s);
  // Species s's coefficients will change in time (TimedDiffusionTerm): its matrix keeps every
  // entry of its scheme's stencil, zeros included, so that re-assembled matrices share one
  // nonzero pattern (the TS integrator copies values into its operator in place). Collective.
  void keep_pattern(int s);
  // New Dirichlet values (one set per species; time-dependent boundary data): the vectors b_s
  // are recomputed, the matrices kept. Returns the species whose M(s) is a new matrix (pinned
  // cells, whose coupling is redone). Collective.
  std::vector<int> set_dirichlet(const std::vector<FaceValues>& dirichlet);
  double scale(int s) const { return scale_[s]; }
  // False where the operator is not symmetric (first-order tensor masks): CG does not apply.
  bool symmetric(int s) const { return symmetric_[s]; }
  // True when any b_s may be non-zero (Dirichlet data or pinned cells).
  bool has_dirichlet() const { return has_dirichlet_; }

private:
  std::shared_ptr<LaplacianMatrix> own_matrix(int s) const;

  const Grid& grid_;
  const Halo& halo_;
  std::vector<const DiffusionOperator*> ops_;
  std::vector<FaceValues> dirichlet_; // per species (empty: none)
  std::vector<std::vector<PetscInt>> pin_rows_;
  std::vector<std::vector<double>> pin_values_;
  std::vector<std::shared_ptr<LaplacianMatrix>> mat_;
  std::vector<int> index_; // which of the matrix's b vectors is species s's
  std::vector<double> scale_;
  std::vector<bool> symmetric_;
  std::vector<bool> keep_pattern_; // per species: zeros of the stencil kept
  std::vector<MatH> pinned_M_;     // per species: own matrix when pinned (else null)
  std::vector<VecH> pinned_b_;
  bool has_dirichlet_ = false;
};

} // namespace morphogen
