#include "integrators/diffusion_solver.hpp"

#include "integrators/ksp_defaults.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/options.hpp"
#include "core/user_error.hpp"

#include <cmath>
#include <petscdmda.h>

namespace morphogen {

DiffusionSolver::DiffusionSolver(const Grid& grid, const OperatorMatrices& ops,
                                 const std::vector<std::string>& species, Options& opt,
                                 const std::vector<std::string>& varying)
    : grid_(grid), ops_(ops), species_(species) {
  const size_t ns = species.size();
  A_.resize(ns);
  ksp_.resize(ns);
  assembled_dt_.assign(ns, -1.0);
  assembled_theta_.assign(ns, -1.0);
  iterations_.assign(ns, 0);
  rhs_ = grid.create_global();
  tmp_ = grid.create_global();
  // Defaults of our KSP prefix, overridable from the options database.
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  for (const char* name :
       {"diffusion_ksp_type", "diffusion_pc_type", "diffusion_ksp_rtol", "diffusion_ksp_atol",
        "diffusion_ksp_max_it", "diffusion_sub_pc_type", "diffusion_pc_mg_levels",
        "diffusion_pc_mg_galerkin", "diffusion_ksp_monitor", "diffusion_ksp_view",
        "diffusion_ksp_converged_reason", "diffusion_pc_hypre_type", "diffusion_ksp_norm_type"})
    opt.known(name);
  for (size_t s = 0; s < ns; ++s)
    configure(static_cast<int>(s));
  choose_spectral(
      opt.choice("diffusion_solver", "auto", {"auto", "ksp", "spectral"},
                 "diffusion substep solver: spectral (exact FFT/DCT solve; periodic "
                 "or zero-flux axes, constant coefficients), ksp, or auto (spectral where it "
                 "applies and no -diffusion_ksp_*/-diffusion_pc_* option is given)"),
      opt.choice("diffusion_slow_axis", "auto", {"auto", "fft", "tridiagonal"},
                 "the spectral solve along the slowest axis (y in 2-D, z in 3-D): tridiagonal "
                 "(elimination after the transform of the other axes: no FFT along it and no "
                 "transposes between the ranks; up to 64 ranks, no cross terms with it), fft "
                 "(the full transform), or auto (tridiagonal where it applies, except on one "
                 "rank in 3-D; else fft)"),
      varying);
}

std::unique_ptr<ExactSolve> auto_exact_solve(const Grid& grid, Mat M, std::string* why) {
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  std::string why_tri;
  if (!(size == 1 && grid.dim() == 3))
    if (auto t = TridiagonalSolver::create(grid, M, &why_tri)) return t;
  return SpectralSolver::create(grid, M, why);
}

// The exact solve of species s: as auto_exact_solve (auto), tridiagonal along the slowest axis
// (tridiagonal: an error where it does not apply) or the full transform (fft); null and *why if
// none.
std::unique_ptr<ExactSolve> DiffusionSolver::exact_for(int s, const std::string& slow,
                                                       std::string* why) {
  if (slow == "auto") return auto_exact_solve(grid_, ops_.M(s), why);
  std::string why_tri;
  if (slow == "tridiagonal") {
    if (auto t = TridiagonalSolver::create(grid_, ops_.M(s), &why_tri)) return t;
    throw UserError("-diffusion_slow_axis tridiagonal: species " + species_[s] + ": " + why_tri +
                    "; allowed here: auto or fft");
  }
  return SpectralSolver::create(grid_, ops_.M(s), why);
}

void DiffusionSolver::choose_spectral(const std::string& mode, const std::string& slow,
                                      const std::vector<std::string>& varying) {
  const int ns = ops_.nspecies();
  spectral_.resize(ns);
  spectral_mat_.assign(ns, nullptr);
  // auto: a user who tunes the KSP (tolerances, types, monitors) gets the KSP.
  bool user_ksp = false;
  for (const char* name :
       {"-diffusion_ksp_type", "-diffusion_pc_type", "-diffusion_ksp_rtol", "-diffusion_ksp_atol",
        "-diffusion_ksp_max_it", "-diffusion_ksp_monitor", "-diffusion_ksp_view",
        "-diffusion_ksp_converged_reason", "-diffusion_ksp_norm_type"}) {
    // (not -diffusion_sub_pc_type: ksp_defaults sets it itself for block Jacobi, and a later
    // Simulation in the same process, a grid level or a sweep point, must not read it as a user's)
    PetscBool set = PETSC_FALSE;
    MG_PETSC(PetscOptionsHasName(nullptr, nullptr, name, &set));
    user_ksp |= set == PETSC_TRUE;
  }
  for (int s = 0; s < ns; ++s) {
    if (ops_.scale(s) == 0.0) continue;
    std::string why;
    if (mode == "ksp")
      why = "-diffusion_solver ksp";
    else if (mode == "auto" && user_ksp)
      why = "a -diffusion_ksp_/-diffusion_pc_ option was given";
    else if (static_cast<size_t>(s) < varying.size() && !varying[s].empty())
      why = varying[s] + ", re-assembled during the run";
    else if (!ops_.symmetric(s))
      why = "a non-symmetric operator";
    else
      spectral_[s] = exact_for(s, slow, &why);
    if (!spectral_[s] && mode == "spectral")
      throw UserError("-diffusion_solver spectral: species " + species_[s] + ": " + why +
                      "; allowed here: ksp or auto");
    if (spectral_[s]) spectral_mat_[s] = ops_.M(s);
    PetscPrintf(grid_.comm(), "  diffusion solve of %s: %s\n", species_[s].c_str(),
                (spectral_[s] ? spectral_[s]->method() : "ksp (" + why + ")").c_str());
  }
}

// The FFT solve stays valid while M_s is the matrix it was checked on and has not been
// re-assembled (operator_changed).
bool DiffusionSolver::use_spectral(int s) {
  if (!spectral_[s]) return false;
  if (!std::isnan(assembled_dt_[s]) && ops_.M(s) == spectral_mat_[s]) return true;
  spectral_[s].reset();
  PetscPrintf(grid_.comm(), "  diffusion solve of %s: ksp (its matrix changed)\n",
              species_[s].c_str());
  return false;
}

namespace {

// Default relative tolerance of the KSP solves (relative to ||rhs||, i.e. to ||u||: the start is
// u^n, so the error left is at most about rtol ||u|| per substep). It only has to sit well below
// the splitting error, which per step is O(dt^3) for Strang (O(dt^2) for Lie) times the
// commutator of reaction and diffusion: at the step sizes where splitting pays (dt of 10-100x
// the explicit bound), that is 1e-5..1e-3 of ||u|| in the decks; 1e-8 is >= 1000x below it and
// saves about a third of the iterations of the former 1e-10. Tests of the order of accuracy
// at small dt set -diffusion_ksp_rtol explicitly.
constexpr double kDefaultRtol = 1e-8;

void check_type_name(const char* option, PetscFunctionList list, const char* what) {
  char value[256];
  PetscBool set = PETSC_FALSE;
  MG_PETSC(PetscOptionsGetString(nullptr, nullptr, (std::string("-") + option).c_str(), value,
                                 sizeof value, &set));
  if (!set) return;
  void (*fn)(void) = nullptr;
  MG_PETSC(PetscFunctionListFind(list, value, &fn));
  if (fn) return;
  throw UserError(std::string("-") + option + " " + value + ": unknown " + what +
                  " type (this PETSc's types are listed by -help with -integrator split)");
}

} // namespace

void DiffusionSolver::configure(int s) {
  int size = 1;
  MPI_Comm_size(grid_.comm(), &size);
  MG_PETSC(KSPCreate(grid_.comm(), ksp_[s].out()));
  KSP ksp = ksp_[s];
  MG_PETSC(KSPSetOptionsPrefix(ksp, "diffusion_"));
  if (ops_.symmetric(s)) {
    set_cg_icc(ksp);
  } else {
    // The first-order tensor masks give a non-symmetric matrix: GMRES with ILU (blocks).
    MG_PETSC(KSPSetType(ksp, KSPGMRES));
    PC pc;
    MG_PETSC(KSPGetPC(ksp, &pc));
    MG_PETSC(PCSetType(pc, size == 1 ? PCILU : PCBJACOBI));
  }
  MG_PETSC(KSPSetTolerances(ksp, kDefaultRtol, 1e-14, PETSC_DEFAULT, 10000));
  // The DMDA lets -diffusion_pc_type mg build its grid hierarchy; the operator is ours.
  MG_PETSC(KSPSetDM(ksp, grid_.dm()));
  MG_PETSC(KSPSetDMActive(ksp, PETSC_FALSE));
  MG_PETSC(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
  // User options are applied now, at setup, so that a bad -diffusion_* value fails before any
  // output is written; unknown KSP/PC type names are reported with the registered ones.
  check_type_name("diffusion_ksp_type", KSPList, "KSP");
  check_type_name("diffusion_pc_type", PCList, "PC");
  const std::string err = petsc_quietly([&] { return KSPSetFromOptions(ksp); });
  if (const std::string named = err.empty() ? "" : name_petsc_option_error("diffusion_", err);
      !named.empty())
    throw UserError(named);
  if (!err.empty())
    throw UserError("-diffusion_ksp_*/-diffusion_pc_* options: PETSc refused them (" +
                    one_line(err) + "); see -help petsc for the KSP and PC types");
  // -diffusion_ksp_type preonly (with a direct PC: lu, cholesky) takes no initial guess.
  PetscBool preonly = PETSC_FALSE;
  MG_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(ksp), KSPPREONLY, &preonly));
  if (preonly) MG_PETSC(KSPSetInitialGuessNonzero(ksp, PETSC_FALSE));
}

void DiffusionSolver::prepare_species(int s, double dt, double theta) {
  if (ops_.scale(s) == 0.0 || (assembled_dt_[s] == dt && assembled_theta_[s] == theta)) return;
  MG_PETSC(MatDuplicate(ops_.M(s), MAT_COPY_VALUES, A_[s].out()));
  MG_PETSC(MatScale(A_[s], -theta * dt * ops_.scale(s)));
  MG_PETSC(MatShift(A_[s], 1.0));
  MG_PETSC(KSPSetOperators(ksp_[s], A_[s], A_[s]));
  if (assembled_dt_[s] < 0 && ops_.symmetric(s)) icc_subblocks(ksp_[s], "-diffusion_sub_pc_type");
  if (assembled_dt_[s] < 0 && !ops_.symmetric(s)) set_up_or_refuse(ksp_[s], "-diffusion_");
  assembled_dt_[s] = dt;
  assembled_theta_[s] = theta;
}

void DiffusionSolver::prepare(double dt, double theta) {
  for (int s = 0; s < ops_.nspecies(); ++s)
    if (!spectral_[s]) prepare_species(s, dt, theta); // (on demand if the FFT solve is dropped)
}

bool DiffusionSolver::solve_local(int s, Vec ulocal, double dt, double theta) {
  if (!solve_local_begin(s, ulocal, dt, theta)) return false;
  solve_local_end(s, ulocal);
  return true;
}

bool DiffusionSolver::solve_local_begin(int s, Vec ulocal, double dt, double theta) {
  if (ops_.scale(s) == 0.0) { // no diffusion: nothing to do (as in solve)
    iterations_[s] = 0;
    return true;
  }
  if (ops_.has_dirichlet() || !use_spectral(s) || !spectral_[s]->steps_local()) return false;
  LogScope log_scope(log_events().diffusion);
  spectral_[s]->step_local_begin(ulocal, dt * ops_.scale(s), theta);
  iterations_[s] = 0;
  return true;
}

bool DiffusionSolver::solve_local_planes_begin(const std::vector<VecH>& u, double dt, double theta,
                                               const std::function<void(PetscInt)>& before) {
  if (ops_.has_dirichlet()) return false;
  std::vector<TridiagonalSolver::GroupMember> group;
  for (int s = 0; s < ops_.nspecies(); ++s) {
    if (ops_.scale(s) == 0.0) continue;
    auto* t = use_spectral(s) ? dynamic_cast<TridiagonalSolver*>(spectral_[s].get()) : nullptr;
    if (!t || !t->steps_local()) return false;
    group.push_back({t, u[static_cast<size_t>(s)], dt * ops_.scale(s), theta});
  }
  if (group.empty()) return false;
  LogScope log_scope(log_events().diffusion);
  TridiagonalSolver::step_local_group_begin(group, before);
  for (int s = 0; s < ops_.nspecies(); ++s)
    iterations_[s] = 0;
  return true;
}

void DiffusionSolver::solve_local_end(int s, Vec ulocal) {
  if (ops_.scale(s) == 0.0) return;
  LogScope log_scope(log_events().diffusion);
  spectral_[s]->step_local_end(ulocal);
}

void DiffusionSolver::solve(int s, Vec u, double dt, double theta, PetscInt step) {
  LogScope log_scope(log_events().diffusion);
  if (ops_.scale(s) == 0.0) {
    iterations_[s] = 0;
    return;
  }
  const double c = dt * ops_.scale(s);
  if (use_spectral(s)) {
    spectral_[s]->step(u, c, theta);
    if (ops_.has_dirichlet()) { // + c (I - theta c M)^-1 b: the boundary data's part
      spectral_[s]->solve_shifted(ops_.b(s), tmp_, c, theta);
      MG_PETSC(VecAXPY(u, c, tmp_));
    }
    iterations_[s] = 0;
    return;
  }
  prepare_species(s, dt, theta);
  // rhs = u + (1 - theta) c L u + c b
  MG_PETSC(VecCopy(u, rhs_));
  if (theta != 1.0) {
    MG_PETSC(MatMult(ops_.M(s), u, tmp_));
    MG_PETSC(VecAXPY(rhs_, (1.0 - theta) * c, tmp_));
  }
  if (ops_.has_dirichlet()) MG_PETSC(VecAXPY(rhs_, c, ops_.b(s)));
  MG_PETSC(KSPSolve(ksp_[s], rhs_, u));
  KSPConvergedReason reason;
  MG_PETSC(KSPGetConvergedReason(ksp_[s], &reason));
  MG_PETSC(KSPGetIterationNumber(ksp_[s], &iterations_[s]));
  total_its_ += iterations_[s];
  if (reason < 0)
    throw UserError("diffusion solve of species " + species_[s] + " diverged at step " +
                    std::to_string(step) + ": KSP reason " + KSPConvergedReasons[reason] +
                    " after " + std::to_string(iterations_[s]) +
                    " iterations; try a smaller -dt or other -diffusion_ksp_type / "
                    "-diffusion_pc_type");
}

} // namespace morphogen
