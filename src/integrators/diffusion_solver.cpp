#include "integrators/diffusion_solver.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"

#include <petscdmda.h>

namespace morphogen {

namespace {

// A neighbour value as a linear combination of in-domain cells plus a constant.
struct Term {
  PetscInt c[3];
  double coef;
};

} // namespace

DiffusionSolver::DiffusionSolver(const Grid& grid, const Halo& halo, const Stencil& stencil,
                                 const std::vector<std::string>& species,
                                 const std::vector<double>& D,
                                 const std::vector<FaceValues>* dirichlet, Options& opt)
    : grid_(grid), halo_(halo), species_(species), D_(D) {
  const size_t ns = species.size();
  A_.assign(ns, nullptr);
  ksp_.assign(ns, nullptr);
  assembled_dt_.assign(ns, -1.0);
  assembled_theta_.assign(ns, -1.0);
  iterations_.assign(ns, 0);
  for (size_t s = 0; s < ns; ++s)
    b_.push_back(grid.create_global());
  rhs_ = grid.create_global();
  tmp_ = grid.create_global();
  has_dirichlet_ = dirichlet != nullptr && !dirichlet->empty();
  assemble_laplacian(stencil, dirichlet);
  // Defaults of our KSP prefix, overridable from the options database.
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  for (const char* name :
       {"diffusion_ksp_type", "diffusion_pc_type", "diffusion_ksp_rtol", "diffusion_ksp_atol",
        "diffusion_ksp_max_it", "diffusion_sub_pc_type", "diffusion_pc_mg_levels",
        "diffusion_pc_mg_galerkin", "diffusion_ksp_monitor", "diffusion_ksp_view",
        "diffusion_ksp_converged_reason", "diffusion_pc_hypre_type"})
    opt.known(name);
  for (size_t s = 0; s < ns; ++s)
    configure(static_cast<int>(s));
}

DiffusionSolver::~DiffusionSolver() {
  for (auto& k : ksp_)
    if (k) (void)KSPDestroy(&k);
  for (auto& a : A_)
    if (a) (void)MatDestroy(&a);
  if (L_) (void)MatDestroy(&L_);
}

void DiffusionSolver::assemble_laplacian(const Stencil& stencil,
                                         const std::vector<FaceValues>* dirichlet) {
  const GridSpec& g = grid_.spec();
  DM dm = grid_.dm();
  MG_PETSC(DMSetMatType(dm, MATAIJ));
  MG_PETSC(DMCreateMatrix(dm, &L_));
  MG_PETSC(MatSetOption(L_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
  const size_t ns = species_.size();
  std::vector<PetscScalar*> barr(ns);
  for (size_t s = 0; s < ns; ++s)
    MG_PETSC(VecGetArray(b_[s], &barr[s]));
  const Box& ob = grid_.owned();
  // Resolve a stencil neighbour q (global indices, possibly outside the domain) into in-domain
  // cells; Dirichlet constants (2 g per species) accumulate into consts with sign `sign`.
  std::vector<double> consts(ns);
  std::vector<Term> terms;
  // q is unwrapped (a position in this rank's ghosted box); as in Halo::fill_boundaries, the
  // highest non-periodic axis on which q is outside decides, recursively.
  auto resolve = [&](auto&& self, PetscInt qi, PetscInt qj, PetscInt qk, double coef) -> void {
    const PetscInt q[3] = {qi, qj, qk};
    int dd = -1;
    for (int d = 0; d < grid_.dim(); ++d)
      if (g.bc[d] != Boundary::Periodic && (q[d] < 0 || q[d] >= g.n[d])) dd = d;
    if (dd < 0) {
      // Periodic coordinates stay unwrapped: MatSetValuesStencil maps ghost positions of
      // this rank's ghosted box through the DMDA's periodic numbering.
      terms.push_back({{q[0], q[1], q[2]}, coef});
      return;
    }
    const int side = q[dd] < 0 ? 0 : 1;
    PetscInt m[3] = {q[0], q[1], q[2]};
    m[dd] = side == 0 ? -q[dd] - 1 : 2 * g.n[dd] - 1 - q[dd];
    if (g.bc[dd] == Boundary::Dirichlet) {
      for (size_t s = 0; s < ns; ++s)
        consts[s] += coef * 2.0 *
                     (*dirichlet)[s].face[2 * dd + side][halo_.face_index(dd, q[0], q[1], q[2])];
      self(self, m[0], m[1], m[2], -coef);
    } else {
      self(self, m[0], m[1], m[2], coef);
    }
  };
  std::vector<MatStencil> cols;
  std::vector<PetscScalar> vals;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        terms.clear();
        std::fill(consts.begin(), consts.end(), 0.0);
        for (int t = 0; t < stencil.nterms; ++t) {
          const PetscInt qi = i + stencil.off[t][0], qj = j + stencil.off[t][1],
                         qk = k + stencil.off[t][2];
          resolve(resolve, qi, qj, qk, stencil.w[t]);
        }
        MatStencil row{};
        row.i = i, row.j = j, row.k = k;
        cols.clear();
        vals.clear();
        for (const Term& tm : terms) {
          MatStencil c{};
          c.i = tm.c[0], c.j = tm.c[1], c.k = tm.c[2];
          cols.push_back(c);
          vals.push_back(tm.coef);
        }
        MG_PETSC(MatSetValuesStencil(L_, 1, &row, static_cast<PetscInt>(cols.size()), cols.data(),
                                     vals.data(), ADD_VALUES));
        for (size_t s = 0; s < ns; ++s)
          barr[s][grid_.owned_index(i, j, k)] = consts[s];
      }
  MG_PETSC(MatAssemblyBegin(L_, MAT_FINAL_ASSEMBLY));
  MG_PETSC(MatAssemblyEnd(L_, MAT_FINAL_ASSEMBLY));
  for (size_t s = 0; s < ns; ++s)
    MG_PETSC(VecRestoreArray(b_[s], &barr[s]));
}

void DiffusionSolver::configure(int s) {
  int size = 1;
  MPI_Comm_size(grid_.comm(), &size);
  KSP& ksp = ksp_[s];
  MG_PETSC(KSPCreate(grid_.comm(), &ksp));
  MG_PETSC(KSPSetOptionsPrefix(ksp, "diffusion_"));
  MG_PETSC(KSPSetType(ksp, KSPCG));
  PC pc;
  MG_PETSC(KSPGetPC(ksp, &pc));
  MG_PETSC(PCSetType(pc, size == 1 ? PCICC : PCBJACOBI));
  MG_PETSC(KSPSetTolerances(ksp, 1e-10, 1e-14, PETSC_DEFAULT, 10000));
  // The DMDA lets -diffusion_pc_type mg build its grid hierarchy; the operator is ours.
  MG_PETSC(KSPSetDM(ksp, grid_.dm()));
  MG_PETSC(KSPSetDMActive(ksp, PETSC_FALSE));
  MG_PETSC(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE));
}

void DiffusionSolver::solve(int s, Vec u, double dt, double theta, PetscInt step) {
  LogScope log_scope(log_events().diffusion);
  if (D_[s] == 0.0) {
    iterations_[s] = 0;
    return;
  }
  const double c = dt * D_[s];
  if (assembled_dt_[s] != dt || assembled_theta_[s] != theta) {
    if (A_[s]) MG_PETSC(MatDestroy(&A_[s]));
    MG_PETSC(MatDuplicate(L_, MAT_COPY_VALUES, &A_[s]));
    MG_PETSC(MatScale(A_[s], -theta * c));
    MG_PETSC(MatShift(A_[s], 1.0));
    MG_PETSC(KSPSetOperators(ksp_[s], A_[s], A_[s]));
    if (assembled_dt_[s] < 0) {
      MG_PETSC(KSPSetFromOptions(ksp_[s]));
      PC pc;
      MG_PETSC(KSPGetPC(ksp_[s], &pc));
      PetscBool bj = PETSC_FALSE, user_sub = PETSC_FALSE;
      MG_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCBJACOBI, &bj));
      MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-diffusion_sub_pc_type", &user_sub));
      MG_PETSC(KSPSetUp(ksp_[s]));
      if (bj && !user_sub) {
        PetscInt nlocal = 0, first = 0;
        KSP* sub = nullptr;
        MG_PETSC(PCBJacobiGetSubKSP(pc, &nlocal, &first, &sub));
        for (PetscInt q = 0; q < nlocal; ++q) {
          PC spc;
          MG_PETSC(KSPGetPC(sub[q], &spc));
          MG_PETSC(PCSetType(spc, PCICC));
        }
      }
    }
    assembled_dt_[s] = dt;
    assembled_theta_[s] = theta;
  }
  // rhs = u + (1 - theta) c L u + c b
  MG_PETSC(VecCopy(u, rhs_));
  if (theta != 1.0) {
    MG_PETSC(MatMult(L_, u, tmp_));
    MG_PETSC(VecAXPY(rhs_, (1.0 - theta) * c, tmp_));
  }
  if (has_dirichlet_) MG_PETSC(VecAXPY(rhs_, c, b_[s]));
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
