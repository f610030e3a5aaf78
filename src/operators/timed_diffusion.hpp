// Diffusion whose coefficients depend on time (-D_S or a tensor value using t), as a diffusion
// term of the run:
//
//   du_s/dt = div(K(x, t) grad u_s)
//
// set_time(t) evaluates the coefficients at t (a function of t filling the owned cells of the
// ghosted coefficient arrays, built by the app layer) and re-sets the species' DiffusionOperator
// (IsotropicField or a tensor scheme), so the explicit operator and, through
// TermList::set_time, the assembled matrix follow. Integrators call it once per step: the
// explicit integrator at the step's start, the split integrator at the diffusion substep's
// midpoint (second order with Crank-Nicolson), TS at its stage times (right-hand side,
// IFunction and IJacobian). Nothing is done when t is the time last evaluated. The stable dt is
// that of the current coefficients (the run checks -dt against it after every explicit step).
#pragma once

#include "operators/diffusion_term.hpp"

#include <functional>

namespace morphogen {

class TimedDiffusionTerm : public DiffusionTerm {
public:
  // Fill coef (one ghosted array per component, zeroed, owned cells to be set) at time t.
  // Collective (it may throw a UserError on every rank).
  using Fill = std::function<void(double t, std::vector<std::vector<double>>& coef)>;

  // `op` (owned by the run) is re-set by set_time(); it holds the coefficients at t = 0.
  TimedDiffusionTerm(int species, std::string name, DiffusionOperator& op, const Halo& halo,
                     int components, Fill fill);

  std::string describe() const override;
  bool timed_coefficients() const override { return true; }
  bool set_time(double t) const override;

private:
  DiffusionOperator& mop_;
  const Halo& halo_;
  int nc_;
  Fill fill_;
  mutable double last_t_ = 0; // the operator holds the coefficients at t = 0 initially
  mutable std::vector<std::vector<double>> scratch_; // next coefficients (reused)
};

} // namespace morphogen
