#include "operators/fluid_solver.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"
#include "grid/prolong.hpp"

#include <petscdmda.h>
#include <petscksp.h>

#include <algorithm>
#include <cmath>

namespace morphogen {

namespace {

const char* kind_text(fluid::Kind k) {
  return k == fluid::Kind::Cavity ? "cavity" : (k == fluid::Kind::Channel ? "channel" : "periodic");
}

// An unknown -<prefix>ksp_type / pc_type name, as a one-line UserError.
void check_type_name(const std::string& option, PetscFunctionList list, const char* what) {
  char value[256];
  PetscBool set = PETSC_FALSE;
  MG_PETSC(
      PetscOptionsGetString(nullptr, nullptr, ("-" + option).c_str(), value, sizeof value, &set));
  if (!set) return;
  void (*fn)(void) = nullptr;
  MG_PETSC(PetscFunctionListFind(list, value, &fn));
  if (!fn)
    throw UserError("-" + option + " " + value + ": unknown " + what +
                    " type (see -help petsc for the registered types)");
}

} // namespace

FluidSolver::FluidSolver(const Grid& grid, FluidSettings settings, const std::vector<double>& solid)
    : grid_(grid), set_(std::move(settings)), halo_(grid) {
  if (grid.dim() != 2)
    throw UserError(set_.option_text + ": the fluid solver is 2-D only (the grid is " +
                    std::to_string(grid.dim()) + "-D; use a 2-D -grid_n nx,ny)");
  const GridSpec& g = grid.spec();
  const bool periodic = set_.kind == fluid::Kind::Periodic;
  if (periodic && (g.bc[0] != Boundary::Periodic || g.bc[1] != Boundary::Periodic))
    throw UserError(set_.option_text + ": needs a periodic grid (-grid_bc periodic)");
  geom_.dim = 2;
  for (int d = 0; d < 3; ++d) {
    geom_.n[d] = g.n[d];
    geom_.periodic[d] = d >= 2 || periodic;
  }
  for (auto& u : u_) {
    u = grid.create_local();
    MG_PETSC(VecSet(u, 0.0));
  }
  solid_ = grid.create_local();
  MG_PETSC(VecSet(solid_, 0.0));
  PetscScalar* s;
  MG_PETSC(VecGetArray(solid_, &s));
  const Box& ob = grid.owned();
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      s[grid.local_index(i, j, 0)] = solid[grid.owned_index(i, j, 0)] > 0.5 ? 1.0 : 0.0;
  MG_PETSC(VecRestoreArray(solid_, &s));
  refresh(solid_);
  PetscInt nl;
  MG_PETSC(VecGetLocalSize(solid_, &nl));
  MG_PETSC(VecGetArray(solid_, &s));
  solidv_.assign(s, s + nl);
  MG_PETSC(VecRestoreArray(solid_, &s));
  build_face_codes();
  p_local_ = grid.create_local();
  MG_PETSC(VecSet(p_local_, 0.0));
  p_ = grid.create_global();
  rhs_ = grid.create_global();
  x_ = grid.create_global();
  MG_PETSC(VecSet(p_, 0.0));
  for (int q = 0; q < 2; ++q)
    configure_ksp(ksp_visc_[q].out(), "fluid_visc_", false);
  configure_ksp(ksp_pois_.out(), "fluid_", true);
  assemble_poisson();
  if (set_.kind == fluid::Kind::Channel) {
    set_velocity([&](double, double, double& u, double& v) { u = set_.inflow, v = 0.0; });
    project();
  }
}

FluidSolver::~FluidSolver() {
  if (null_) MatNullSpaceDestroy(&null_);
}

void FluidSolver::configure_ksp(KSP* ksp, const char* prefix, bool poisson) {
  MG_PETSC(KSPCreate(grid_.comm(), ksp));
  MG_PETSC(KSPSetOptionsPrefix(*ksp, prefix));
  MG_PETSC(KSPSetType(*ksp, KSPCG));
  PC pc;
  MG_PETSC(KSPGetPC(*ksp, &pc));
  MG_PETSC(PCSetType(pc, poisson ? PCGAMG : PCJACOBI));
  MG_PETSC(KSPSetTolerances(*ksp, poisson ? 1e-8 : 1e-10, 1e-14, PETSC_DEFAULT, 10000));
  MG_PETSC(KSPSetDM(*ksp, grid_.dm())); // for -fluid_pc_type mg's grid hierarchy
  MG_PETSC(KSPSetDMActive(*ksp, PETSC_FALSE));
  MG_PETSC(KSPSetInitialGuessNonzero(*ksp, PETSC_TRUE));
  // The true residual: ||div u_f|| after the projection is at most rtol ||div u_f|| before.
  MG_PETSC(KSPSetNormType(*ksp, KSP_NORM_UNPRECONDITIONED));
  const std::string p = prefix;
  check_type_name(p + "ksp_type", KSPList, "KSP");
  check_type_name(p + "pc_type", PCList, "PC");
  const std::string err = petsc_quietly([&] { return KSPSetFromOptions(*ksp); });
  if (err.empty()) {
    // -fluid_ksp_type preonly (with a direct PC: lu, cholesky) takes no initial guess.
    PetscBool preonly = PETSC_FALSE;
    MG_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(*ksp), KSPPREONLY, &preonly));
    if (preonly) MG_PETSC(KSPSetInitialGuessNonzero(*ksp, PETSC_FALSE));
    return;
  }
  const std::string named = name_petsc_option_error(p, err);
  throw UserError(!named.empty() ? named
                                 : "-" + p + "ksp_*/-" + p + "pc_* options: PETSc refused them (" +
                                       one_line(err) + ")");
}

void FluidSolver::copy_owned(Vec local, Vec global, bool to_local) const {
  PetscScalar *a, *g;
  MG_PETSC(VecGetArray(local, &a));
  MG_PETSC(VecGetArray(global, &g));
  const Box& ob = grid_.owned();
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      double& l = a[grid_.local_index(i, j, 0)];
      double& o = g[grid_.owned_index(i, j, 0)];
      if (to_local)
        l = o;
      else
        o = l;
    }
  MG_PETSC(VecRestoreArray(global, &g));
  MG_PETSC(VecRestoreArray(local, &a));
}

void FluidSolver::refresh(Vec local) const {
  PetscScalar* a;
  MG_PETSC(VecGetArray(local, &a));
  halo_.begin(a);
  halo_.end(a);
  MG_PETSC(VecRestoreArray(local, &a));
}

bool FluidSolver::solid(PetscInt i, PetscInt j) const {
  return solidv_[static_cast<size_t>(grid_.local_index(i, j, 0))] > 0.5;
}

PetscInt FluidSolver::neighbour(PetscInt i, int d, int s, bool& outside) const {
  const PetscInt n = i + s; // unwrapped: a periodic grid's ghost layer holds the image
  outside = !geom_.periodic[d] && (n < 0 || n >= geom_.n[d]);
  return n;
}

const fluid::Face& FluidSolver::face(PetscInt i, PetscInt j, int d, int s) const {
  return face_of(grid_.owned_index(i, j, 0), d, s);
}

// Each owned cell's faces: a boundary face where the neighbour lies outside a non-periodic
// grid, closed where the cell or its neighbour is solid, else open.
void FluidSolver::build_face_codes() {
  face_table_[0] = fluid::open_face();
  face_table_[1] = fluid::solid_face();
  for (int d = 0; d < 2; ++d)
    for (int s = 0; s < 2; ++s)
      face_table_[2 + 2 * d + s] =
          fluid::boundary_face(set_.kind, d, 2 * s - 1, set_.lid, set_.inflow);
  const Box& ob = grid_.owned();
  face_code_.assign(static_cast<size_t>(4 * ob.size()), 0);
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      for (int d = 0; d < 2; ++d)
        for (int s = 0; s < 2; ++s) {
          bool outside = false;
          const PetscInt n = neighbour(d == 0 ? i : j, d, 2 * s - 1, outside);
          const bool closed = !outside && (solid(i, j) || (d == 0 ? solid(n, j) : solid(i, n)));
          face_code_[static_cast<size_t>(4 * grid_.owned_index(i, j, 0) + 2 * d + s)] =
              static_cast<std::uint8_t>(outside ? 2 + 2 * d + s : (closed ? 1 : 0));
        }
}

void FluidSolver::zero_solid(Vec local) const {
  const PetscScalar* s;
  PetscScalar* a;
  MG_PETSC(VecGetArrayRead(solid_, &s));
  MG_PETSC(VecGetArray(local, &a));
  PetscInt n;
  MG_PETSC(VecGetLocalSize(local, &n));
  for (PetscInt c = 0; c < n; ++c)
    if (s[c] > 0.5) a[c] = 0.0;
  MG_PETSC(VecRestoreArray(local, &a));
  MG_PETSC(VecRestoreArrayRead(solid_, &s));
}

void FluidSolver::set_velocity(const std::function<void(double, double, double&, double&)>& f) {
  PetscScalar *u, *v;
  MG_PETSC(VecGetArray(u_[0], &u));
  MG_PETSC(VecGetArray(u_[1], &v));
  const Box& ob = grid_.owned();
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      const PetscInt c = grid_.local_index(i, j, 0);
      f(grid_.centre(0, i), grid_.centre(1, j), u[c], v[c]);
    }
  MG_PETSC(VecRestoreArray(u_[1], &v));
  MG_PETSC(VecRestoreArray(u_[0], &u));
  zero_solid(u_[0]);
  zero_solid(u_[1]);
}

void FluidSolver::step(double dt) {
  const double h = dt / set_.substeps;
  for (int k = 0; k < set_.substeps; ++k)
    substep(h);
}

void FluidSolver::substep(double h) {
  advect_velocity(h);
  diffuse(h);
  project();
}

double FluidSolver::speed_bound() const {
  double m = 0;
  for (const auto& u : u_) {
    double a = 0;
    MG_PETSC(VecNorm(u, NORM_INFINITY, &a)); // local Vec: this rank's cells
    m = std::max(m, a);
  }
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, grid_.comm());
  const double wall = set_.kind == fluid::Kind::Cavity
                          ? std::fabs(set_.lid)
                          : (set_.kind == fluid::Kind::Channel ? std::fabs(set_.inflow) : 0.0);
  return 2.0 * std::max(m, wall); // flows around obstacles speed up; the stage checks each step
}

std::string FluidSolver::kind_name() const {
  return kind_text(set_.kind);
}

std::vector<std::pair<std::string, Vec>> FluidSolver::state() const {
  return {{"velocity_x", u_[0]}, {"velocity_y", u_[1]}, {"fluid_pressure", p_local_}};
}

void FluidSolver::state_restored() {
  for (auto& u : u_)
    refresh(u);
  copy_owned(p_local_, p_, false); // the next pressure solve starts from the restored p
  refresh(p_local_);
}

void FluidSolver::prolong_from(FluidSolver& coarse) {
  coarse.state_restored(); // its ghosts current
  const auto from = coarse.state(), to = state();
  for (size_t i = 0; i < to.size(); ++i) {
    const PetscScalar* c;
    PetscScalar* f;
    MG_PETSC(VecGetArrayRead(from[i].second, &c));
    MG_PETSC(VecGetArray(to[i].second, &f));
    prolong_cell_centred(coarse.grid_, c, grid_, f);
    MG_PETSC(VecRestoreArray(to[i].second, &f));
    MG_PETSC(VecRestoreArrayRead(from[i].second, &c));
  }
  zero_solid(u_[0]);
  zero_solid(u_[1]);
  state_restored();
  project();
}

std::string FluidSolver::describe() const {
  std::string b = set_.kind == fluid::Kind::Cavity
                      ? "lid speed " + format_number(set_.lid)
                      : (set_.kind == fluid::Kind::Channel ? "inflow " + format_number(set_.inflow)
                                                           : "periodic");
  KSPType kt;
  PCType pt;
  PC pc;
  MG_PETSC(KSPGetType(ksp_pois_, &kt));
  MG_PETSC(KSPGetPC(ksp_pois_, &pc));
  MG_PETSC(PCGetType(pc, &pt));
  return std::string("stable fluids: ") + kind_text(set_.kind) + " (" + b + "), viscosity " +
         format_number(set_.viscosity) + ", " + std::to_string(set_.substeps) +
         " substep(s) per step, " + (set_.interp == advect::Interp::Cubic ? "cubic" : "linear") +
         " self-advection, pressure solve " +
         (spectral_pois_ ? std::string("spectral (FFT/DCT, exact)") : std::string(kt) + "/" + pt);
}

void fluid_ksp_solve(KSP ksp, Vec b, Vec x, const std::string& what, const std::string& prefix) {
  const std::string err = petsc_quietly([&] { return KSPSolve(ksp, b, x); });
  if (err.empty()) return;
  throw UserError(what + ": PETSc could not run the solve with the -" + prefix + "ksp_*/-" +
                  prefix + "pc_* options (" + one_line(err) + ")" +
                  (err.find("KSPSetDM") != std::string::npos
                       ? "; with -" + prefix + "pc_type mg add -" + prefix + "pc_mg_galerkin both"
                       : ""));
}

} // namespace morphogen
