// Operator-splitting integrator (unconditionally stable for the diffusion part), a list of
// substeps (split_substeps):
//
//   Lie (first order):     u <- D(dt) R(dt) u
//   Strang (second order): u <- R(dt/2) D(dt) R(dt/2) u
//
// R(dt) is the reaction substep du/dt = R(u; p) + S(x, t) solved cell by cell
// (reaction_kernel.hpp: explicit Euler or Heun, or implicit backward Euler or trapezoidal by
// Newton with the model's analytic Jacobian, as in the stable-ARD paper's Appendix A but for
// every model); a cell that fails to converge stops the run with its global index, values and
// residual. The reaction pass runs in place, row by row, prefetching the rows two ahead where a
// rank's state does not fit the per-core caches (core/prefetch.hpp). D(dt) is the implicit
// diffusion substep (diffusion_solver.hpp: backward Euler or Crank-Nicolson, theta = 1 or 1/2).
// Second order needs Strang with Crank-Nicolson and a second-order reaction scheme (Heun or
// trapezoidal). The clamp floor is applied after the reaction substeps and at the end of the step.
// Diffusion coefficients and Dirichlet values using t are set at the diffusion substep's
// midpoint, t + dt/2 (TermList::set_time; the matrices of the species whose coefficients changed
// are re-assembled, constant-in-time runs untouched). Fused Strang (steps(), when nothing observes
// the state between the n steps of a pass): the reaction half-steps of consecutive steps merge into
// one,
//   R(dt/2) D(dt) [R(dt) D(dt)]^(n-1) R(dt/2),
// the same order (second) with n - 1 fewer reaction substeps; a pass of 1 step is step(). Where
// every species' diffusion is the in-place tridiagonal solve and no constraint acts between the
// substeps, a reaction substep followed by a diffusion substep (the first R of a step, a merged
// R(dt)) runs inside the diffusion's first pass, plane by plane of the slowest axis just before
// the transforms read the plane (SplitSettings::fuse_planes): the same arithmetic (bitwise the
// same states), one pass over the state less per step.
#pragma once

#include "fields/param_set.hpp"
#include "fields/source_terms.hpp"
#include "integrators/diffusion_solver.hpp"
#include "integrators/integrator.hpp"
#include "integrators/reaction_kernel.hpp"
#include "operators/term_list.hpp"

#include <functional>
#include <string>
#include <vector>

namespace morphogen {

// A row of reaction substeps (reaction_row's signature); a std::function so that a model built
// at run time can carry its kinetics.
using ReactionRowFn =
    std::function<int(ReactionScheme, int, const double* const*, const double* const*,
                      const double*, const double* const*, const double* const*, double, double,
                      int, const double*, double* const*, CellSolve*)>;

enum class SplitOrdering { Lie, Strang };

// One substep of a split step: the reaction (with sources) or the diffusion over a fraction of
// dt. Lie is {R 1, D 1}; Strang is {R 1/2, D 1, R 1/2}.
struct Substep {
  enum class Kind { Reaction, Diffusion } kind;
  double fraction;
};
std::vector<Substep> split_substeps(SplitOrdering ordering);

struct SplitSettings {
  SplitOrdering ordering = SplitOrdering::Strang;
  ReactionScheme reaction = ReactionScheme::Trapezoidal;
  double theta = 0.5; // diffusion: 1 backward Euler, 0.5 Crank-Nicolson
  double newton_tol = 1e-12;
  int newton_max_it = 20;
  bool fuse_planes = true; // a reaction substep before a diffusion one inside the latter's pass
};

class SplitIntegrator : public Integrator {
public:
  SplitIntegrator(const Grid& grid, ReactionRowFn fn, const std::vector<std::string>& species,
                  const ParamSet& params, std::vector<double> floor, SourceTerms* sources,
                  DiffusionSolver& diffusion, const SplitSettings& settings);

  // One step from t to t + dt on the ghosted local state vectors (owned cells updated).
  void step(std::vector<VecH>& u, double t, double dt, PetscInt step) override;

  // n >= 1 Strang steps from t in one pass (fused reaction half-steps, see above); `first` is the
  // number of the pass's first step. Needs fuse_unsupported() empty.
  void steps(std::vector<VecH>& u, double t, double dt, PetscInt first, int n);
  // Why steps() cannot fuse this run ("" if it can): Lie ordering, coefficients that follow the
  // state or t (they are refreshed per step).
  std::string fuse_unsupported() const;

  // The run's constraints (pinned cells, clamp floor), applied after every reaction substep
  // and at the end of the step (without: the clamp floor only).
  void use_constraints(const TermList& terms) { terms_ = &terms; }

  // Largest Newton iteration count of the last reaction substep.
  int last_newton_iterations() const { return last_its_; }
  // Reaction substeps taken inside the diffusion's pass so far (SplitSettings::fuse_planes).
  long planes_fused_substeps() const { return planes_fused_; }

private:
  struct ReactionPass;
  void react(std::vector<VecH>& u, double t0, double dt, PetscInt step);
  void react_open(ReactionPass& r, std::vector<VecH>& u, double t0, double dt, PetscInt step);
  void react_row(ReactionPass& r, PetscInt j, PetscInt k);
  void react_rows(ReactionPass& r);
  void react_close(ReactionPass& r, std::vector<VecH>& u);
  void react_diffuse(std::vector<VecH>& u, double t0, double dt_react, PetscInt react_step,
                     double dt_diffuse, PetscInt diffuse_step);
  void diffuse(std::vector<VecH>& u, double dt, PetscInt step);
  void constrain(std::vector<VecH>& u) const;

  const Grid& grid_;
  ReactionRowFn fn_;
  std::vector<std::string> species_;
  const ParamSet& params_;
  std::vector<double> floor_;
  SourceTerms* sources_;
  const TermList* terms_ = nullptr;
  DiffusionSolver& diffusion_;
  SplitSettings set_;
  std::vector<Substep> substeps_;
  std::vector<std::vector<double>> const_rows_;
  VecH global_;
  int last_its_ = 0;
  long planes_fused_ = 0;
  bool prefetch_ = false; // the reaction pass prefetches rows (the rank's state >= 8 MiB)
};

} // namespace morphogen
