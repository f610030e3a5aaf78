// PETSc TS integrator (IMEX additive Runge-Kutta):
//
//   du_s/dt = K_s u_s                      (implicit: stiff, linear; the species' diffusion
//                                           operator scale_s (M_s u + b_s))
//           + R_s(u; p) + S_s(x, t)        (explicit: reaction and source terms, cell by cell)
//
// M_s, scale_s and b_s come from operators/operator_matrices.hpp (the explicit scheme's
// operator with the boundary conditions folded in).
//
// Layout: one MPI Vec X holds every species; this rank's block is species 0's owned cells
// (owned layout, x fastest), then species 1's, ... (local size nspecies * owned cells). The
// implicit operator is blockdiag(scale_s M_s) in that layout, assembled once by copying the rows
// with column indices mapped to the block layout; the IJacobian shift*I - blockdiag(D_s L) is
// refreshed from it only when the shift changes (so a fixed dt factors the preconditioner once).
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
//     Newton, converging at a rate ~ dt |dR/du|). Explicit types (euler, rk, ssp) are refused.
//   -ksp_type cg, -pc_type icc on one rank / bjacobi with icc blocks in parallel (unless
//     -sub_pc_type is given), -ksp_rtol 1e-10.
// Consecutive step() calls continue one TS integration (multistep schemes keep their history)
// unless the state or the time changed in between (the clamp floor acted, or a restart): then
// the step is restarted (TSRestartStep).
// A diverged TS, SNES or KSP throws UserError from step() naming the step, time and PETSc's
// reasons. Callbacks never let an exception into PETSc: they record it, return an error code,
// and step() rethrows it after TSSolve returns.
#pragma once

#include "fields/param_set.hpp"
#include "fields/source_terms.hpp"
#include "operators/operator_matrices.hpp"

#include <exception>
#include <petscts.h>
#include <string>
#include <vector>

namespace morphogen {

class TsIntegrator {
public:
  using RatesFn = void (*)(const double* u, const double* p, double* r);

  // D and floor have one entry per species (floor -inf: no clamp). `sources` may be null. dt is
  // the step of step() calls (and the largest internal step when adaptive); the integrator
  // keeps references to grid, params, lap and sources.
  TsIntegrator(const Grid& grid, RatesFn rates, const std::vector<std::string>& species,
               const ParamSet& params, std::vector<double> floor, const OperatorMatrices& ops,
               SourceTerms* sources, double dt);
  TsIntegrator(const TsIntegrator&) = delete;
  TsIntegrator& operator=(const TsIntegrator&) = delete;

  // Advance the ghosted local state vectors (owned cells) from t to t + dt (TS may take
  // several internal steps when adaptive), then apply the clamp floor. `step` is for messages.
  void step(std::vector<VecH>& u, double t, double dt, PetscInt step);

  PetscInt total_steps() const { return steps_; }       // accepted internal TS steps so far
  PetscInt total_rejected() const { return rejected_; } // rejected internal TS steps so far
  bool adaptive() const { return adaptive_; }
  TS ts() const { return ts_.get(); }

private:
  static PetscErrorCode ifunction_cb(TS, PetscReal t, Vec X, Vec Xdot, Vec F, void* ctx);
  static PetscErrorCode rhsfunction_cb(TS, PetscReal t, Vec X, Vec G, void* ctx);
  static PetscErrorCode ijacobian_cb(TS, PetscReal t, Vec X, Vec Xdot, PetscReal shift, Mat A,
                                     Mat P, void* ctx);
  PetscErrorCode ifunction(Vec X, Vec Xdot, Vec F);
  PetscErrorCode rhsfunction(PetscReal t, Vec X, Vec G);
  PetscErrorCode ijacobian(PetscReal shift, Mat A, Mat P);
  PetscErrorCode fill_jacobian(PetscReal shift);

  void build_operator();
  void setup_ts(double dt);
  // Owned cells between the ghosted local state and X; into X it returns whether any value
  // differed from X's (this rank).
  bool copy_state(std::vector<VecH>& u, bool to_x);

  const Grid& grid_;
  RatesFn rates_;
  std::vector<std::string> species_;
  const ParamSet& params_;
  std::vector<double> floor_;
  const OperatorMatrices& ops_;
  SourceTerms* sources_;
  PetscInt ns_ = 0, nloc_ = 0;

  VecH X_, bD_;              // block state; block D_s b_s (Dirichlet data)
  bool has_b_ = false;       // any Dirichlet data at all
  MatH Dblock_;              // blockdiag(scale_s M_s)
  MatH J_;                   // shift I - Dblock
  PetscReal jac_shift_ = -1; // shift J_ holds (-1: stale)
  TSH ts_;                   // destroyed before the matrices it uses
  bool adaptive_ = false;
  double next_dt_ = 0; // the adaptive controller's proposal for the next internal step
  bool solved_ = false;

  std::exception_ptr callback_error_;
  std::vector<double> cell_u_, cell_p_, cell_r_;
  PetscInt steps_ = 0, rejected_ = 0;
};

} // namespace morphogen
