// PETSc TS integrator on a DM (TSSetDM): the run's term list (operators/term_list.hpp) as
//
//   du/dt = K u + b                 (implicit: the diffusion terms, linear; K = blockdiag of
//                                    the species' operators scale_s (M_s u + b_s), from
//                                    operators/operator_matrices.hpp)
//         + G(u, x, t)              (explicit right-hand side: every other term, reaction and
//                                    sources included, evaluated on a ghosted copy of the state)
//
// With -ts_diffusion explicit the diffusion terms join G instead (no implicit part): explicit
// TS types only (euler, rk, ssp), e.g. classical RK4 with -ts_type rk -ts_rk_type 4.
//
// Layout: the state X is a global Vec of a DMDA with one dof per species (interlaced,
// DMDACreateCompatibleDMDA of the run's grid: same decomposition and stencil). The right-hand
// side scatters X to a local Vec with DMGlobalToLocal (inter-rank and periodic ghosts), fills the
// ghosts outside non-periodic faces (zero flux, Dirichlet data), and lets each term add its
// rates. The implicit operator K is assembled once in the interlaced numbering (row
// nspecies * g + s for cell g of the scalar DMDA); the IJacobian shift*I - K is refreshed from it
// only when the shift changes (so a fixed dt factors the preconditioner once).
//
// Defaults (all overridable from the options database, no prefix: -ts_*, -snes_*, -ksp_*,
// -pc_*, -sub_pc_*):
//   -ts_type arkimex -ts_arkimex_type 2e: second order, 3 stages with an explicit first
//     stage; the implicit part is an L-stable, stiffly accurate ESDIRK (gamma = 1 - 1/sqrt 2,
//     Constantinescu's ARK2, cf. Giraldo, Kelly & Constantinescu 2013), and 2e is the explicit
//     companion PETSc marks optimal for a linear implicit part, which ours is; it carries an
//     embedded first-order pair for -ts_adapt_type basic. Chosen over ars122 and a2 because their
//     implicit parts (implicit midpoint, trapezoidal) are only A-stable: like Crank-Nicolson
//     they leave the stiffest diffusion modes oscillating at large dt, where 2e damps them.
//   -ts_adapt_type none: fixed dt (one TS step per step() call); with -ts_adapt_type basic
//     (and -ts_rtol/-ts_atol) TS takes as many internal steps as it needs, never longer than
//     dt, landing exactly on t + dt (TS_EXACTFINALTIME_MATCHSTEP).
//   -snes_type ksponly: the implicit part of an IMEX scheme (arkimex, rosw, eimex) is linear,
//     so one linear solve per stage is exact. Fully implicit types (-ts_type bdf, cn, beuler,
//     theta, ..., or -ts_arkimex_fully_implicit) also put the reaction into the solve: for
//     them the default becomes -snes_type newtonls, with the diffusion-only Jacobian (modified
//     Newton, converging at a rate ~ dt |dR/du|). Explicit types (euler, rk, ssp) are refused
//     unless -ts_diffusion explicit (then the default is -ts_type rk, PETSc's 3bs).
//   -ts_diffusion_solver auto: where every diffusing species' operator has an exact solve
//     (constant coefficients on periodic / zero-flux / Dirichlet axes, checked numerically:
//     operators/spectral_solver.hpp, tridiagonal_solver.hpp; Dirichlet values may follow t),
//     no coefficient follows t or the state, and no -ksp_type, -pc_type, -sub_pc_type, -ksp_rtol,
//     -ksp_atol or -ksp_max_it is given: -ksp_type preonly with the exact inverse of J as the
//     preconditioner (integrators/ts_exact_pc.hpp), one application per stage. Elsewhere (and with
//     ksp): -ksp_type cg, -pc_type icc on one rank / bjacobi with icc blocks in parallel (unless
//     -sub_pc_type is given), -ksp_rtol 1e-10; GMRES + ILU for non-symmetric operators
//     (first-order tensor masks). The choice is printed at setup.
// Consecutive step() calls continue one TS integration (multistep schemes keep their history)
// unless the state or the time changed in between (the clamp floor acted, or a restart): then
// the step is restarted (TSRestartStep).
// Diffusion coefficients and Dirichlet values using t are evaluated at the stage times: every
// callback (right-hand side, IFunction, IJacobian) first sets the terms to its t
// (TermList::set_time), and K and b are refreshed in place when they changed.
// A diverged TS, SNES or KSP throws UserError from step() naming the step, time and PETSc's
// reasons. Callbacks never let an exception into PETSc: they record it, return an error code,
// and step() rethrows it after TSSolve returns.
#pragma once

#include "integrators/integrator.hpp"
#include "integrators/ts_exact_pc.hpp"
#include "operators/operator_matrices.hpp"
#include "operators/term_list.hpp"

#include <exception>
#include <memory>
#include <petscts.h>
#include <string>
#include <vector>

namespace morphogen {

class TsIntegrator : public Integrator {
public:
  // `terms` holds one diffusion term per species; `ops` their matrices (boundary conditions
  // folded in), or null for -ts_diffusion explicit (diffusion in the right-hand side). dt is
  // the step of step() calls (and the largest internal step when adaptive). The integrator
  // keeps references to grid, halo, terms, ops and dirichlet.
  TsIntegrator(const Grid& grid, const Halo& halo, const std::vector<std::string>& species,
               const TermList& terms, const OperatorMatrices* ops,
               const std::vector<FaceValues>* dirichlet, double dt,
               const std::string& solver = "auto");
  TsIntegrator(const TsIntegrator&) = delete;
  TsIntegrator& operator=(const TsIntegrator&) = delete;

  // Advance the ghosted local state vectors (owned cells) from t to t + dt (TS may take
  // several internal steps when adaptive), then apply the constraints. `step` is for messages.
  void step(std::vector<VecH>& u, double t, double dt, PetscInt step) override;

  PetscInt total_steps() const { return steps_; }       // accepted internal TS steps so far
  PetscInt total_rejected() const { return rejected_; } // rejected internal TS steps so far
  bool adaptive() const { return adaptive_; }
  bool implicit_diffusion() const { return ops_ != nullptr; }
  TS ts() const { return ts_.get(); }
  DM dm() const { return dm_.get(); }

private:
  static PetscErrorCode ifunction_cb(TS, PetscReal t, Vec X, Vec Xdot, Vec F, void* ctx);
  static PetscErrorCode rhsfunction_cb(TS, PetscReal t, Vec X, Vec G, void* ctx);
  static PetscErrorCode ijacobian_cb(TS, PetscReal t, Vec X, Vec Xdot, PetscReal shift, Mat A,
                                     Mat P, void* ctx);
  PetscErrorCode ifunction(Vec X, Vec Xdot, Vec F);
  PetscErrorCode rhsfunction(PetscReal t, Vec X, Vec G);
  void add_rhs_terms(const PetscScalar* xl, double t, PetscScalar* g) const;
  PetscErrorCode ijacobian(PetscReal shift, Mat A, Mat P);
  PetscErrorCode fill_jacobian(PetscReal shift);

  void build_operator();
  void fill_operator();
  // Coefficients and Dirichlet values using t, at a stage time (from the callbacks): the
  // implicit operator and its data follow in place (same nonzero pattern).
  void at_time(double t);
  void setup_ts(double dt);
  void setup_implicit_solver(double dt);
  // -ts_diffusion_solver: installs the exact preconditioner on ksp where it applies (true), or
  // says why not (false; an error with spectral).
  bool try_exact_pc(KSP ksp);
  std::string exact_pc_blocker() const;
  void check_exact_kept(KSP ksp);
  void iterative_defaults(KSP ksp, bool symmetric, bool user_ksp, bool user_pc);
  void check_type();
  // Owned cells between the ghosted local state and X; into X it returns whether any value
  // differed from X's (this rank).
  bool copy_state(std::vector<VecH>& u, bool to_x);

  const Grid& grid_;
  const Halo& halo_;
  std::vector<std::string> species_;
  const TermList& terms_;
  const OperatorMatrices* ops_;
  const std::vector<FaceValues>* dirichlet_;
  std::vector<const Term*> rhs_; // the terms of G
  HaloNeed rhs_halo_;
  PetscInt ns_ = 0, nloc_ = 0;

  DMH dm_;                   // DMDA with one dof per species
  VecH X_, bD_;              // state; interlaced scale_s b_s (Dirichlet data)
  bool has_b_ = false;       // any Dirichlet data at all
  MatH Dblock_;              // K without b
  MatH J_;                   // shift I - K
  PetscReal jac_shift_ = -1; // shift J_ holds (-1: stale)
  PetscReal pc_shift_ = 0;   // shift of the last IJacobian (the exact preconditioner's; 0: none)
  std::string solver_;       // -ts_diffusion_solver
  std::unique_ptr<TsExactPc> exact_pc_; // the shell PC's context: outlives ts_
  TSH ts_;                              // destroyed before the matrices and DM it uses
  bool adaptive_ = false;
  double next_dt_ = 0; // the adaptive controller's proposal for the next internal step
  bool solved_ = false;
  bool timed_ = false; // some coefficient or boundary value depends on t

  std::exception_ptr callback_error_;
  PetscInt steps_ = 0, rejected_ = 0;
};

} // namespace morphogen
