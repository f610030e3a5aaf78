// Self-advection and implicit viscosity of the stable-fluids solver
// (operators/fluid_solver.hpp).
#include "operators/fluid_solver.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"

#include <petscdmda.h>
#include <petscksp.h>

#include <algorithm>
#include <cmath>

namespace morphogen {

namespace {
constexpr int kMaxFluidHalo = 64; // cells, as the advection stage's widest halo
} // namespace

// u* = u^n at the departure point of each fluid cell (rk2 back-trace with u^n itself).
void FluidSolver::advect_velocity(double h) {
  const Box& ob = grid_.owned();
  const double dth[3] = {h / grid_.spec().h(0), h / grid_.spec().h(1), 0.0};
  double umax[2] = {0, 0};
  for (int d = 0; d < 2; ++d)
    MG_PETSC(VecNorm(u_[d], NORM_INFINITY, &umax[d])); // owned cells and (current) ghosts
  MPI_Allreduce(MPI_IN_PLACE, umax, 2, MPI_DOUBLE, MPI_MAX, grid_.comm());
  const double courant = std::max(umax[0] * dth[0], umax[1] * dth[1]);
  const long long need = advect::advection_reach(courant, set_.interp);
  if (need > kMaxFluidHalo)
    throw UserError(set_.option_text + ": the velocity back-trace of a fluid substep reaches " +
                    std::to_string(need) + " cells (Courant number " + format_number(courant) +
                    "), more than " + std::to_string(kMaxFluidHalo) +
                    "; use a smaller -dt or more -fluid_substeps");
  if (!wide_ || need > wide_->width()) {
    wide_ = std::make_unique<WideHalo>(
        grid_, static_cast<int>(std::min<long long>(need + 2, kMaxFluidHalo)));
    for (int d = 0; d < 2; ++d) {
      geom_.s[d] = wide_->box().s[d];
      geom_.m[d] = wide_->box().m[d];
      wu_[d].resize(static_cast<size_t>(wide_->size()));
    }
  }
  PetscScalar* a[2];
  for (int d = 0; d < 2; ++d) {
    MG_PETSC(VecGetArray(u_[d], &a[d]));
    wide_->fill(a[d], wu_[d].data());
  }
  const double* w[3] = {wu_[0].data(), wu_[1].data(), nullptr};
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      const PetscInt c = grid_.local_index(i, j, 0);
      if (solid(i, j)) {
        a[0][c] = a[1][c] = 0.0;
        continue;
      }
      double X[3];
      advect::backtrace(w, geom_, i, j, 0, dth, advect::Backtrace::Rk2, X);
      for (int d = 0; d < 2; ++d)
        a[d][c] = advect::interpolate(w[d], geom_, X, set_.interp);
    }
  for (int d = 0; d < 2; ++d)
    MG_PETSC(VecRestoreArray(u_[d], &a[d]));
}

// (I - h nu L) per component with the face rules of fluid_kernel.hpp; b: the wall values.
void FluidSolver::assemble_viscous(double h) {
  const Box& ob = grid_.owned();
  const double hx[2] = {grid_.spec().h(0), grid_.spec().h(1)};
  const double c = h * set_.viscosity;
  for (int q = 0; q < 2; ++q) {
    A_visc_[q].reset();
    MG_PETSC(DMCreateMatrix(grid_.dm(), A_visc_[q].out()));
    b_visc_[q] = grid_.create_global();
    PetscScalar* b;
    MG_PETSC(VecGetArray(b_visc_[q], &b));
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        MatStencil row{0, j, i, 0}, cols[5];
        PetscScalar vals[5] = {1.0, 0, 0, 0, 0};
        int n = 1;
        cols[0] = row;
        double rhs = 0.0;
        for (int d = 0; d < 2 && !solid(i, j); ++d)
          for (int s = -1; s <= 1; s += 2) {
            double diag, nb, r;
            fluid::viscous_weights(face(i, j, d, s), q, c, hx[d], diag, nb, r);
            vals[0] += diag;
            rhs += r;
            if (nb == 0.0) continue;
            cols[n] = row;
            (d == 0 ? cols[n].i : cols[n].j) += s;
            vals[n++] = nb;
          }
        b[grid_.owned_index(i, j, 0)] = rhs;
        MG_PETSC(MatSetValuesStencil(A_visc_[q], 1, &row, n, cols, vals, INSERT_VALUES));
      }
    MG_PETSC(VecRestoreArray(b_visc_[q], &b));
    MG_PETSC(MatAssemblyBegin(A_visc_[q], MAT_FINAL_ASSEMBLY));
    MG_PETSC(MatAssemblyEnd(A_visc_[q], MAT_FINAL_ASSEMBLY));
    MG_PETSC(KSPSetOperators(ksp_visc_[q], A_visc_[q], A_visc_[q]));
    spectral_visc_[q] = spectral_for(A_visc_[q], "-fluid_visc_");
  }
  if (visc_h_ < 0)
    PetscPrintf(grid_.comm(), "  fluid viscosity solve: %s\n",
                spectral_viscosity() ? "spectral (FFT/DCT/DST, exact)" : "ksp");
  visc_h_ = h;
}

void FluidSolver::diffuse(double h) {
  if (set_.viscosity == 0.0) return;
  if (h != visc_h_) assemble_viscous(h);
  for (int q = 0; q < 2; ++q) {
    copy_owned(u_[q], x_, false);
    MG_PETSC(VecWAXPY(rhs_, 1.0, x_, b_visc_[q]));
    if (spectral_visc_[q]) {
      spectral_visc_[q]->solve_negated(rhs_, x_);
      copy_owned(u_[q], x_, true);
      continue;
    }
    fluid_ksp_solve(ksp_visc_[q], rhs_, x_, set_.option_text + " viscosity solve", "fluid_visc_");
    KSPConvergedReason reason;
    MG_PETSC(KSPGetConvergedReason(ksp_visc_[q], &reason));
    if (reason < 0)
      throw UserError(set_.option_text + ": the viscosity solve diverged (KSP reason " +
                      KSPConvergedReasons[reason] +
                      "); try other -fluid_visc_ksp_type / -fluid_visc_pc_type");
    copy_owned(u_[q], x_, true);
  }
}

} // namespace morphogen
