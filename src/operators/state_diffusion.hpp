// Diffusion whose coefficients depend on the species' own state (polar a(theta), gradient-shaped
// tensors: operators/polar_kernel.hpp), as a diffusion term of the run:
//
//   du_s/dt = div(K(x, grad u_s) grad u_s)
//
// refresh(u) recomputes the coefficients from u_s and re-sets the species' DiffusionOperator
// (IsotropicField: face coefficient the mean of the two cells, stable-ARD eq. 17; Tensor: the
// second-order conservative scheme), so the explicit operator and the assembled matrix both
// follow (the matrix stays symmetric: CG + ICC apply). The gradient is the central difference
// of u_s over ghosts exchanged here and mirrored outside every non-periodic face (whatever the
// boundary type), so the coefficients depend on the owned state only: the same numbers on any
// rank count. The explicit integrator refreshes every step; the split and TS integrators once at
// the start of each step (coefficients lagged over the step). The stable dt is from the a-priori
// bound of the rule (max over all states), not from the current coefficients.
#pragma once

#include "operators/diffusion_term.hpp"

#include <memory>

namespace morphogen {

// The coefficients of one cell as a function of the state's gradient there.
class CoefficientRule {
public:
  virtual ~CoefficientRule() = default;
  virtual DiffusionScheme scheme() const = 0; // IsotropicField or Tensor(FirstOrder)
  virtual int components() const = 0;         // 1, or TensorLayout<dim>::nc
  // Bound on the largest eigenvalue of K over the grid and every state.
  virtual double max_eigenvalue() const = 0;
  virtual std::string describe() const = 0;
  // Coefficients coef[components()] of the owned cell with ghosted index c, gradient g[dim].
  virtual void at(PetscInt c, const double* g, double* coef) const = 0;
};

class StateDiffusionTerm : public DiffusionTerm {
public:
  // `op` (owned by the run) is re-set by refresh(); built with rule's scheme and components.
  StateDiffusionTerm(int species, std::string name, DiffusionOperator& op, const Halo& halo,
                     std::unique_ptr<CoefficientRule> rule);

  std::string describe() const override;
  double stable_dt() const override;
  bool refresh(const std::vector<VecH>& u) const override;

  // The coefficients from a ghosted array of u_s (owned cells set). Collective.
  void refresh_from(const double* u) const;

private:
  DiffusionOperator& mop_;
  const Halo& halo_;
  std::unique_ptr<CoefficientRule> rule_;
  mutable std::vector<double> buf_;
  mutable std::vector<std::vector<double>> coef_scratch_; // next coefficients (reused)
};

} // namespace morphogen
