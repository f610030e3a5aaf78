// Implicit diffusion substep, one linear solve per species:
//
//   (I - theta dt D_s L) u_s^{n+1} = (I + (1 - theta) dt D_s L) u_s^n + dt D_s b_s
//
// theta = 1: backward Euler; theta = 1/2: Crank-Nicolson. D_s (L + b_s) is the species'
// diffusion operator (operators/operator_matrices.hpp: scale_s (M_s + b_s); for constant
// isotropic diffusion D_s times the stencil's Laplacian), assembled once on the DMDA: for a
// neighbour outside a zero-flux boundary the coefficient moves to its mirror cell
// (u_ghost = u_inside); outside a Dirichlet boundary it moves with a minus sign and the constant
// 2 g w goes into b_s (u_ghost = 2 g - u_inside) - the same ghost rules as the explicit halo,
// so L u + b equals the explicit scheme's Laplacian. The matrices A_s are assembled once per
// (dt, theta) and reused. Solver: KSP CG with ICC on one rank and block Jacobi with ICC blocks
// in parallel (GMRES with ILU for the non-symmetric first-order tensor masks), relative
// tolerance 1e-8 (see kDefaultRtol in the .cpp); every choice can be overridden with
// -diffusion_ksp_* and -diffusion_pc_* options (e.g. -diffusion_pc_type mg for geometric multigrid
// on the DMDA, -diffusion_pc_type hypre, or -diffusion_ksp_type richardson -diffusion_pc_type
// jacobi or sor for Sanderson's relaxation). A diverged solve is reported with species, KSP reason
// and iteration count. -diffusion_solver auto|ksp|spectral: a species whose matrix is a
// constant-coefficient stencil on periodic / zero-flux axes (checked numerically,
// operators/spectral_solver.hpp) is solved exactly by FFT/DCT instead, on any number of ranks
// (auto: wherever it applies and no -diffusion_ksp_*/-diffusion_pc_* option is given, else KSP;
// spectral: an error where it does not apply). A species whose matrix is known at setup to be
// re-assembled during the run (`varying`: coefficients using t or the state) gets KSP under
// auto and is an error under spectral; one re-assembled otherwise (operator_changed) goes back
// to KSP. The choice per species is printed at setup.
#pragma once

#include "core/options.hpp"
#include "grid/halo.hpp"
#include "grid/stencil.hpp"
#include "operators/operator_matrices.hpp"
#include "operators/spectral_solver.hpp"
#include "operators/tridiagonal_solver.hpp"

#include <cmath>
#include <functional>
#include <memory>
#include <petscksp.h>
#include <string>
#include <vector>

namespace morphogen {

// The exact solve of operator M that -diffusion_slow_axis auto picks: tridiagonal along the
// slowest axis (except on one rank in 3-D, where the full transform measured faster:
// docs/performance.md), else the full transform; null, with *why set, where neither applies.
std::unique_ptr<ExactSolve> auto_exact_solve(const Grid& grid, Mat M, std::string* why);

class DiffusionSolver {
public:
  // ops: the species' diffusion operators as matrices (kept by reference). varying: per species,
  // why its matrix will be re-assembled during the run ("" or missing: it will not).
  DiffusionSolver(const Grid& grid, const OperatorMatrices& ops,
                  const std::vector<std::string>& species, Options& opt,
                  const std::vector<std::string>& varying = {});
  DiffusionSolver(const DiffusionSolver&) = delete;
  DiffusionSolver& operator=(const DiffusionSolver&) = delete;

  // Assemble A_s and set the solvers up for (dt, theta) now (so that every -diffusion_ option,
  // sub-solver ones included, is read at setup); solve() does it on demand otherwise.
  void prepare(double dt, double theta);
  // Solve for species s in place on the global Vec u. `step` is for messages.
  void solve(int s, Vec u, double dt, double theta, PetscInt step);
  // The same on the owned cells of a ghosted local vector, where species s's exact solve works
  // on it in place (no Dirichlet data); false (nothing done) elsewhere: then copy to a global
  // vector and call solve.
  bool solve_local(int s, Vec ulocal, double dt, double theta);
  // solve_local in two halves (ExactSolve::step_local_begin/end: one species' wait for the other
  // ranks overlaps the next species' solve). begin returns false (nothing done) where
  // solve_local would; after a true begin, call end before ulocal is used.
  bool solve_local_begin(int s, Vec ulocal, double dt, double theta);
  void solve_local_end(int s, Vec ulocal);
  // Every species' solve_local_begin at once, where each diffusing species (at least one) is
  // solved by the tridiagonal method in place: their first passes run in lockstep plane by plane
  // of the slowest axis and before(g) is called once for every owned plane g (global index)
  // before any solve reads it (TridiagonalSolver::step_local_group_begin). False (nothing done,
  // before not called) elsewhere. After a true begin, solve_local_end for every species.
  bool solve_local_planes_begin(const std::vector<VecH>& u, double dt, double theta,
                                const std::function<void(PetscInt)>& before);

  // Species s's matrix was re-assembled (solution-dependent coefficients, lagged per step):
  // A_s is rebuilt on the next solve.
  void operator_changed(int s) { assembled_dt_[s] = std::nan(""); }

  // True while species s is solved by FFT (operators/spectral_solver.hpp).
  bool spectral(int s) const { return spectral_[s] != nullptr; }
  PetscInt last_iterations(int s) const { return iterations_[s]; }
  PetscInt total_iterations() const { return total_its_; }
  const OperatorMatrices& operators() const { return ops_; }

private:
  void configure(int s);
  void choose_spectral(const std::string& mode, const std::string& slow,
                       const std::vector<std::string>& varying);
  std::unique_ptr<ExactSolve> exact_for(int s, const std::string& slow, std::string* why);
  bool use_spectral(int s);
  void prepare_species(int s, double dt, double theta);

  const Grid& grid_;
  const OperatorMatrices& ops_;
  std::vector<std::string> species_;
  std::vector<KSPH> ksp_; // (PETSc reference-counts the operators they hold)
  std::vector<MatH> A_;
  std::vector<std::unique_ptr<ExactSolve>> spectral_; // null: KSP
  std::vector<Mat> spectral_mat_;                     // the M_s it was checked on
  std::vector<double> assembled_dt_, assembled_theta_;
  std::vector<PetscInt> iterations_;
  PetscInt total_its_ = 0;
  VecH rhs_, tmp_;
};

} // namespace morphogen
