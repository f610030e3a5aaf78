// The exact inverse of -integrator ts's implicit diffusion Jacobian (TsIntegrator), used as a
// PCSHELL under KSPPREONLY: one application per stage solve, no iteration, no tolerance.
//
//   J = shift I - blockdiag(scale_s M_s)              (species interlaced per cell)
//   J^-1 r = blockdiag( (1 / shift) (I - (scale_s / shift) M_s)^-1 ) r,
//
// each block by the species' exact solve (operators/exact_solve.hpp, ExactSolve::solve_shifted
// with theta = 1: FFT/DCT, or tridiagonal along the slowest axis), exact to rounding for any
// shift, so adaptive steps and every stage of a scheme use it as they come. A species with
// scale_s = 0 (no diffusion) is r_s / shift. The shift is read at each application from the
// integrator (the one its IJacobian last set).
#pragma once

#include "grid/grid.hpp"
#include "operators/exact_solve.hpp"

#include <exception>
#include <memory>
#include <petscksp.h>
#include <vector>

namespace morphogen {

class TsExactPc {
public:
  // solves[s]: species s's exact solve (null only where scale[s] == 0); shift: where the
  // integrator keeps the IJacobian's shift; error: where an exception of an application is
  // kept for the integrator to rethrow after the solve (none may cross PETSc's C code).
  TsExactPc(const Grid& grid, std::vector<std::unique_ptr<ExactSolve>> solves,
            std::vector<double> scale, const PetscReal* shift, std::exception_ptr* error);
  TsExactPc(const TsExactPc&) = delete;
  TsExactPc& operator=(const TsExactPc&) = delete;

  // ksp becomes preonly with this shell preconditioner (the object must outlive ksp's solves).
  void install(KSP ksp);
  // "spectral (FFT/DCT, exact)" or the like, per species, for the setup log.
  std::string method(int s) const;

private:
  static PetscErrorCode apply_cb(PC pc, Vec r, Vec z);
  void apply(Vec r, Vec z);

  std::vector<std::unique_ptr<ExactSolve>> solves_;
  std::vector<double> scale_;
  const PetscReal* shift_;
  std::exception_ptr* error_;
  PetscInt ns_ = 0, nloc_ = 0;
  VecH rs_, zs_; // one species in the grid's global layout
};

} // namespace morphogen
