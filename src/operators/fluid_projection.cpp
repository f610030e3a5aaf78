// The pressure projection of the stable-fluids solver (operators/fluid_solver.hpp): the matrix
// A = -(D G) of the face rules (fluid_kernel.hpp), the solve A p = -div(u_f) and the velocity
// correction.
#include "operators/fluid_solver.hpp"

#include "core/user_error.hpp"

#include <petscdmda.h>
#include <petscksp.h>

#include <cmath>

namespace morphogen {

void FluidSolver::assemble_poisson() {
  MG_PETSC(DMCreateMatrix(grid_.dm(), A_pois_.out()));
  const Box& ob = grid_.owned();
  const double h[2] = {grid_.spec().h(0), grid_.spec().h(1)};
  int closed = 1; // no outflow face anywhere: p is defined up to a constant on the fluid
  VecH ones = grid_.create_global();
  PetscScalar* one;
  MG_PETSC(VecGetArray(ones, &one));
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      MatStencil row{0, j, i, 0}, cols[5];
      PetscScalar vals[5];
      int n = 1;
      cols[0] = row;
      vals[0] = 0.0;
      one[grid_.owned_index(i, j, 0)] = solid(i, j) ? 0.0 : 1.0;
      for (int d = 0; d < 2 && !solid(i, j); ++d)
        for (int s = -1; s <= 1; s += 2) {
          const fluid::Face f = face(i, j, d, s);
          double diag, nb;
          fluid::poisson_weights(f, h[d], diag, nb);
          vals[0] += diag;
          if (f.proj == fluid::ProjFace::Outflow) closed = 0;
          if (nb == 0.0) continue;
          cols[n] = row;
          (d == 0 ? cols[n].i : cols[n].j) += s;
          vals[n++] = nb;
        }
      if (vals[0] == 0.0) vals[0] = 1.0; // a solid cell (or a fluid cell walled in on all sides)
      MG_PETSC(MatSetValuesStencil(A_pois_, 1, &row, n, cols, vals, INSERT_VALUES));
    }
  MG_PETSC(VecRestoreArray(ones, &one));
  MG_PETSC(MatAssemblyBegin(A_pois_, MAT_FINAL_ASSEMBLY));
  MG_PETSC(MatAssemblyEnd(A_pois_, MAT_FINAL_ASSEMBLY));
  MPI_Allreduce(MPI_IN_PLACE, &closed, 1, MPI_INT, MPI_MIN, grid_.comm());
  if (closed) {
    MG_PETSC(VecNormalize(ones, nullptr));
    Vec v = ones;
    MG_PETSC(MatNullSpaceCreate(grid_.comm(), PETSC_FALSE, 1, &v, &null_));
    MG_PETSC(MatSetNullSpace(A_pois_, null_));
  }
  MG_PETSC(KSPSetOperators(ksp_pois_, A_pois_, A_pois_));
  choose_pressure_solver();
}

void FluidSolver::choose_pressure_solver() {
  spectral_pois_ = spectral_for(A_pois_, "-fluid_");
}

// An exact FFT/DCT/DST solver of A x = r where A (the pressure or a viscosity matrix) is diagonal
// in the transform of the grid's axes with even (mirror) or odd (wall value) rules at
// non-periodic faces, i.e. nothing breaks the translation invariance (an obstacle, an inflow or
// outflow face): checked numerically on -A. Null (KSP) otherwise, or when the user set one of
// the KSP's options (prefix: "-fluid_" or "-fluid_visc_").
std::unique_ptr<SpectralSolver> FluidSolver::spectral_for(Mat A, const std::string& prefix) {
  for (const char* opt :
       {"ksp_type", "pc_type", "ksp_rtol", "ksp_atol", "ksp_max_it", "ksp_monitor"}) {
    PetscBool set = PETSC_FALSE;
    MG_PETSC(PetscOptionsHasName(nullptr, nullptr, (prefix + opt).c_str(), &set));
    if (set) return nullptr; // a user tuning the KSP gets the KSP
  }
  MatH neg;
  MG_PETSC(MatDuplicate(A, MAT_COPY_VALUES, neg.out()));
  MG_PETSC(MatScale(neg, -1.0));
  std::array<AxisKind, 3> odd = axis_kinds(grid_);
  for (AxisKind& k : odd)
    if (k != AxisKind::Periodic) k = AxisKind::Odd;
  std::string why;
  for (const auto& kinds : {axis_kinds(grid_), odd})
    if (auto sp = SpectralSolver::create(grid_, neg, &why, kinds)) return sp;
  return nullptr;
}

// rhs = -div(u_f) at the fluid cells (0 at solid cells); returns sum of div^2 over this rank.
// face(o, d, s): the face of owned cell o on side s of axis d; solid: the ghosted solid mask.
namespace {
template <class FaceOf>
double divergence_rhs(const Grid& grid, const double* const u[2], double* rhs, const FaceOf& face,
                      const double* solid) {
  const Box& ob = grid.owned();
  const double h[2] = {grid.spec().h(0), grid.spec().h(1)};
  double sum = 0.0;
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      double div = 0.0;
      const PetscInt c = grid.local_index(i, j, 0), o = grid.owned_index(i, j, 0);
      for (int d = 0; d < 2 && !(solid[c] > 0.5); ++d)
        for (int s = -1; s <= 1; s += 2) {
          const PetscInt n = d == 0 ? grid.local_index(i + s, j, 0) : grid.local_index(i, j + s, 0);
          const fluid::Face& f = face(o, d, s);
          const double un = f.proj == fluid::ProjFace::Open ? u[d][n] : 0.0;
          div += s * fluid::face_velocity(f, u[d][c], un) / h[d];
        }
      rhs[o] = -div;
      sum += div * div;
    }
  return sum;
}
} // namespace

void FluidSolver::solve_pressure_ksp() {
  fluid_ksp_solve(ksp_pois_, rhs_, p_, set_.option_text + " pressure solve", "fluid_");
  KSPConvergedReason reason;
  MG_PETSC(KSPGetConvergedReason(ksp_pois_, &reason));
  MG_PETSC(KSPGetIterationNumber(ksp_pois_, &poisson_its_));
  total_poisson_its_ += poisson_its_;
  if (reason < 0)
    throw UserError(set_.option_text + ": the pressure solve diverged (KSP reason " +
                    KSPConvergedReasons[reason] + " after " + std::to_string(poisson_its_) +
                    " iterations); try other -fluid_ksp_type / -fluid_pc_type");
}

void FluidSolver::project() {
  refresh(u_[0]);
  refresh(u_[1]);
  auto faceof = [this](PetscInt o, int d, int s) -> const fluid::Face& { return face_of(o, d, s); };
  PetscScalar *ua, *va, *r;
  MG_PETSC(VecGetArray(u_[0], &ua));
  MG_PETSC(VecGetArray(u_[1], &va));
  const double* u[2] = {ua, va};
  MG_PETSC(VecGetArray(rhs_, &r));
  double before = divergence_rhs(grid_, u, r, faceof, solidv_.data());
  MG_PETSC(VecRestoreArray(rhs_, &r));
  if (null_) MG_PETSC(MatNullSpaceRemove(null_, rhs_));
  if (spectral_pois_) {
    spectral_pois_->solve_negated(rhs_, p_);
    poisson_its_ = 0;
  } else {
    solve_pressure_ksp();
  }
  copy_owned(p_local_, p_, true);
  refresh(p_local_);
  const PetscScalar* p;
  MG_PETSC(VecGetArrayRead(p_local_, &p));
  const Box& ob = grid_.owned();
  const double h[2] = {grid_.spec().h(0), grid_.spec().h(1)};
  // Corrected face divergence (diagnostic) with the old cell velocities, then the cell update.
  double after = 0.0;
  std::vector<double> du[2];
  for (auto& x : du)
    x.assign(static_cast<size_t>(ob.size()), 0.0);
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      const PetscInt c = grid_.local_index(i, j, 0), o = grid_.owned_index(i, j, 0);
      if (solidv_[static_cast<size_t>(c)] > 0.5) continue;
      double div = 0.0;
      for (int d = 0; d < 2; ++d) {
        double gsum = 0.0;
        int open = 0;
        for (int s = -1; s <= 1; s += 2) {
          const PetscInt n =
              d == 0 ? grid_.local_index(i + s, j, 0) : grid_.local_index(i, j + s, 0);
          const fluid::Face& f = face_of(o, d, s);
          const bool is_open = f.proj != fluid::ProjFace::Closed;
          const double pn = f.proj == fluid::ProjFace::Open ? p[n] : 0.0;
          const double gf = fluid::face_gradient(f, s, p[c], pn, h[d]);
          const double un = f.proj == fluid::ProjFace::Open ? u[d][n] : 0.0;
          div += s * (fluid::face_velocity(f, u[d][c], un) - gf) / h[d];
          gsum += gf;
          open += is_open;
        }
        du[d][static_cast<size_t>(o)] = open ? gsum / open : 0.0;
      }
      after += div * div;
    }
  MG_PETSC(VecRestoreArrayRead(p_local_, &p));
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      for (int d = 0; d < 2; ++d)
        (d == 0 ? ua : va)[grid_.local_index(i, j, 0)] -=
            du[d][static_cast<size_t>(grid_.owned_index(i, j, 0))];
  MG_PETSC(VecRestoreArray(u_[1], &va));
  MG_PETSC(VecRestoreArray(u_[0], &ua));
  double sums[2] = {before, after};
  MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE, MPI_SUM, grid_.comm());
  div_ratio_ = sums[0] > 0.0 ? std::sqrt(sums[1] / sums[0]) : 0.0;
}

} // namespace morphogen
