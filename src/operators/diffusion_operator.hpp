// The diffusion term of one species, div(K grad u), on the run's grid:
//   Constant        K = D I with D a number: D times the run's Laplacian stencil (5pt, 7pt,
//                   9pt); the explicit fast path's operator.
//   IsotropicField  K = D(x) I, face coefficients the mean of the two cells.
//   Tensor          K = a symmetric positive definite tensor field, the second-order
//                   conservative discretisation of operators/diffusion_kernel.hpp.
//   TensorFirstOrder  the same tensor with Witkin and Kass's constant masks (sigma : grad grad u,
//                   no tensor-gradient terms; du/dn = 0 at zero-flux walls; not conservative
//                   where sigma varies).
// Coefficient fields are copied into ghosted arrays once (they do not change during a run);
// their ghosts come from the halo exchange and, outside non-periodic faces, from the mirror
// cell (a tensor's off-diagonal component with the sign of the reflection), so that no flux
// of the second-order scheme crosses a zero-flux face; dual cells straddling a zero-flux face use
// the tangential tensor under n.sigma grad u = 0 (second order at the wall). At a Dirichlet face
// the boundary flux omits sigma_nt dg/dt (first order there when g varies along a face with
// sigma_nt != 0; the matrix stays symmetric). The weights of an owned cell are the same numbers for
// the explicit sweep (apply_row) and for the matrix assembly (weights), so L u + b is the explicit
// operator.
#pragma once

#include "grid/halo.hpp"
#include "grid/stencil.hpp"
#include "operators/diffusion_kernel.hpp"

#include <utility>
#include <vector>

namespace morphogen {

class DiffusionOperator {
public:
  // Constant isotropic diffusion D times `stencil`.
  DiffusionOperator(const Grid& grid, const Stencil& stencil, double D);
  // A coefficient field (scheme IsotropicField: one array; tensors: TensorLayout<dim>::nc
  // arrays, components xx, xy, yy or xx, xy, xz, yy, yz, zz), each in ghosted layout with the
  // owned cells set. Collective.
  DiffusionOperator(const Grid& grid, const Halo& halo, DiffusionScheme scheme,
                    std::vector<std::vector<double>> coef);

  // New coefficient arrays (same scheme and component count; owned cells set): ghosts, dual
  // tensors and max_eigenvalue() are redone (solution-dependent coefficients,
  // operators/state_diffusion.hpp). The arrays are swapped: coef gets the previous ones back,
  // for the caller to reuse without allocating. Collective.
  void set_coefficients(std::vector<std::vector<double>>& coef, const Halo& halo) {
    coef_.swap(coef);
    finish_setup(halo);
  }

  const Grid& grid() const { return grid_; }
  DiffusionScheme scheme() const { return scheme_; }
  bool constant() const { return scheme_ == DiffusionScheme::Constant; }
  double D() const { return D_; } // Constant only
  const Stencil& stencil() const { return stencil_; }
  // True when the ghost corners are read (cross terms or the 9pt stencil).
  bool box() const;
  // True when the assembled matrix is symmetric (all but the first-order tensor scheme).
  bool symmetric() const { return scheme_ != DiffusionScheme::TensorFirstOrder; }
  // Largest eigenvalue of K over the grid (D for Constant).
  double max_eigenvalue() const { return lmax_; }
  // Spectral radius bound of the operator: lambda_max(K) times the spectral radius of the
  // run's isotropic Laplacian (exact for Constant; for the tensor schemes a bound on the
  // Rayleigh quotient). The explicit step is stable for dt <= 2 / radius().
  double radius() const { return radius_; }

  // Weights of owned cell (i, j, k) on the 3^dim box, index TensorLayout<dim>::box(dx, dy, dz)
  // (in 2-D the dz = 0 layer: 9 entries).
  void weights(PetscInt i, PetscInt j, PetscInt k, double* w) const;
  // out[m] = (L u) at the n cells starting at ghosted index c (u: ghosted array, ghosts current).
  void apply_row(const double* u, PetscInt c, int n, double* out) const;
  // The constant stencil of the spatial-mean coefficients (for linear stability). Collective.
  Stencil mean_stencil() const;

private:
  void finish_setup(const Halo& halo);
  void build_dual_tensors();
  void zero_flux_dual(PetscInt i, PetscInt j, PetscInt k, PetscInt l);

  const Grid& grid_;
  DiffusionScheme scheme_;
  double D_ = 0, lmax_ = 0, radius_ = 0;
  Stencil stencil_;                       // Constant: the run's stencil (unscaled)
  std::vector<std::vector<double>> coef_; // ghosted layout
  std::vector<std::vector<double>> dual_; // Tensor: dual-cell tensors by lower cell
  std::vector<long> delta_;               // ghosted-array offset of each box neighbour
  long st_[3] = {1, 0, 0};                // ghosted-array stride per axis
  double inv_h_[3] = {1, 1, 1};
  double iso_radius_ = 0; // spectral radius of the 5/7-point Laplacian
};

} // namespace morphogen
