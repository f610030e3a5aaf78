#include "integrators/ts_integrator.hpp"

#include "integrators/diffusion_solver.hpp"
#include "integrators/ksp_defaults.hpp"

#include "core/log_events.hpp"
#include "core/user_error.hpp"

#include <petscdmda.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace morphogen {

namespace {

// Restores PETSc's previous error handler on scope exit (exception-safe).
struct QuietPetscErrors {
  QuietPetscErrors() { (void)PetscPushErrorHandler(PetscReturnErrorHandler, nullptr); }
  ~QuietPetscErrors() { (void)PetscPopErrorHandler(); }
  QuietPetscErrors(const QuietPetscErrors&) = delete;
  QuietPetscErrors& operator=(const QuietPetscErrors&) = delete;
};

} // namespace

TsIntegrator::TsIntegrator(const Grid& grid, const Halo& halo,
                           const std::vector<std::string>& species, const TermList& terms,
                           const OperatorMatrices* ops, const std::vector<FaceValues>* dirichlet,
                           double dt, const std::string& solver)
    : grid_(grid), halo_(halo), species_(species), terms_(terms), ops_(ops), dirichlet_(dirichlet),
      solver_(solver) {
  ns_ = static_cast<PetscInt>(species.size());
  nloc_ = grid.owned().size();
  terms_.diffusion(static_cast<int>(ns_)); // throws unless one diffusion term per species
  if (ops_ && ops_->nspecies() != static_cast<int>(ns_))
    throw std::logic_error("TsIntegrator: species and operator matrices disagree");
  // The right-hand side: every term but the diffusion when that is implicit.
  const auto in_rhs = [this](const Term& t) {
    return !(ops_ && t.kind() == Term::Kind::Diffusion);
  };
  for (const auto& t : terms_.terms())
    if (in_rhs(*t)) rhs_.push_back(t.get());
  rhs_halo_ = terms_.halo(in_rhs);
  if (rhs_halo_.width > grid.spec().stencil_width || (rhs_halo_.box && !grid.spec().box_stencil))
    throw std::logic_error("TsIntegrator: a term needs more halo than the grid has");
  MG_PETSC(DMDACreateCompatibleDMDA(grid.dm(), ns_, dm_.out()));
  MG_PETSC(DMCreateGlobalVector(dm_, X_.out()));
  MG_PETSC(VecSet(X_, 0.0));
  timed_ = terms_.any_time_dependent();
  try {
    if (ops_) build_operator();
    setup_ts(dt);
  } catch (...) {
    ts_.reset();
    J_.reset();
    Dblock_.reset();
    throw;
  }
}

// K = blockdiag(scale_s M_s) in the interlaced numbering, and the interlaced Dirichlet data.
void TsIntegrator::build_operator() {
  MPI_Comm comm = grid_.comm();
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  // Ownership ranges of the DMDA's global (PETSc-ordered) vectors: L's row/column numbering.
  std::vector<PetscInt> ranges(static_cast<size_t>(size) + 1);
  {
    VecH g = grid_.create_global();
    const PetscInt* r = nullptr;
    MG_PETSC(VecGetOwnershipRanges(g, &r));
    std::copy(r, r + size + 1, ranges.begin());
  }
  const PetscInt rstart = ranges[rank], rend = ranges[rank + 1];
  if (rend - rstart != nloc_) throw std::logic_error("TsIntegrator: DMDA ownership mismatch");
  const PetscInt nb = ns_ * nloc_;

  std::vector<PetscInt> dnz(static_cast<size_t>(nb)), onz(static_cast<size_t>(nb));
  for (PetscInt s = 0; s < ns_; ++s) {
    Mat L = ops_->M(static_cast<int>(s));
    for (PetscInt g = rstart; g < rend; ++g) {
      PetscInt nc = 0;
      const PetscInt* cols = nullptr;
      MG_PETSC(MatGetRow(L, g, &nc, &cols, nullptr));
      PetscInt d = 0;
      for (PetscInt c = 0; c < nc; ++c)
        d += cols[c] >= rstart && cols[c] < rend;
      const PetscInt o = nc - d;
      MG_PETSC(MatRestoreRow(L, g, &nc, &cols, nullptr)); // (zeroes nc)
      dnz[static_cast<size_t>(ns_ * (g - rstart) + s)] = d;
      onz[static_cast<size_t>(ns_ * (g - rstart) + s)] = o;
    }
  }
  MG_PETSC(MatCreate(comm, Dblock_.out()));
  MG_PETSC(MatSetSizes(Dblock_, nb, nb, PETSC_DETERMINE, PETSC_DETERMINE));
  MG_PETSC(MatSetType(Dblock_, MATAIJ));
  MG_PETSC(MatSeqAIJSetPreallocation(Dblock_, 0, dnz.data()));
  MG_PETSC(MatMPIAIJSetPreallocation(Dblock_, 0, dnz.data(), 0, onz.data()));
  bD_.reset();
  fill_operator();
  MG_PETSC(MatDuplicate(Dblock_, MAT_COPY_VALUES, J_.out()));
}

// The values of K and of the interlaced Dirichlet data (Dblock_ preallocated or assembled with
// the pattern of the M_s).
void TsIntegrator::fill_operator() {
  MPI_Comm comm = grid_.comm();
  PetscInt rstart = 0, rend = 0;
  {
    VecH g = grid_.create_global();
    MG_PETSC(VecGetOwnershipRange(g, &rstart, &rend));
  }
  // Cell g of the scalar DMDA, species s -> row/column of the interlaced DMDA.
  auto block_col = [&](PetscInt g, PetscInt s) { return ns_ * g + s; };
  std::vector<PetscInt> bcols;
  std::vector<PetscScalar> bvals;
  for (PetscInt s = 0; s < ns_; ++s) {
    Mat L = ops_->M(static_cast<int>(s));
    const double scale = ops_->scale(static_cast<int>(s));
    for (PetscInt g = rstart; g < rend; ++g) {
      PetscInt nc = 0;
      const PetscInt* cols = nullptr;
      const PetscScalar* vals = nullptr;
      MG_PETSC(MatGetRow(L, g, &nc, &cols, &vals));
      bcols.resize(static_cast<size_t>(nc));
      bvals.resize(static_cast<size_t>(nc));
      const PetscInt row = block_col(g, s);
      for (PetscInt c = 0; c < nc; ++c) {
        bcols[static_cast<size_t>(c)] = block_col(cols[c], s);
        bvals[static_cast<size_t>(c)] = scale * vals[c];
      }
      // Kept even where the scale is 0: the pattern (with its diagonal) stays that of M_s.
      MG_PETSC(MatSetValues(Dblock_, 1, &row, nc, bcols.data(), bvals.data(), INSERT_VALUES));
      MG_PETSC(MatRestoreRow(L, g, &nc, &cols, &vals));
    }
  }
  MG_PETSC(MatAssemblyBegin(Dblock_, MAT_FINAL_ASSEMBLY));
  MG_PETSC(MatAssemblyEnd(Dblock_, MAT_FINAL_ASSEMBLY));

  // Interlaced Dirichlet data scale_s b_s.
  if (!bD_) MG_PETSC(VecDuplicate(X_, bD_.out()));
  PetscScalar* bd = nullptr;
  MG_PETSC(VecGetArray(bD_, &bd));
  int local_b = 0;
  for (PetscInt s = 0; s < ns_; ++s) {
    const PetscScalar* b = nullptr;
    const double scale = ops_->scale(static_cast<int>(s));
    MG_PETSC(VecGetArrayRead(ops_->b(static_cast<int>(s)), &b));
    for (PetscInt c = 0; c < nloc_; ++c) {
      bd[ns_ * c + s] = scale * b[c];
      local_b |= bd[ns_ * c + s] != 0.0;
    }
    MG_PETSC(VecRestoreArrayRead(ops_->b(static_cast<int>(s)), &b));
  }
  MG_PETSC(VecRestoreArray(bD_, &bd));
  int any_b = 0;
  MPI_Allreduce(&local_b, &any_b, 1, MPI_INT, MPI_LOR, comm);
  has_b_ = any_b != 0;
}

void TsIntegrator::setup_ts(double dt) {
  MG_PETSC(TSCreate(grid_.comm(), ts_.out()));
  MG_PETSC(TSSetDM(ts_, dm_));
  MG_PETSC(TSSetType(ts_, ops_ ? TSARKIMEX : TSRK));
  if (ops_) MG_PETSC(TSARKIMEXSetType(ts_, TSARKIMEX2E));
  MG_PETSC(TSSetProblemType(ts_, TS_NONLINEAR));
  if (ops_) {
    MG_PETSC(TSSetIFunction(ts_, nullptr, ifunction_cb, this));
    MG_PETSC(TSSetIJacobian(ts_, J_, J_, ijacobian_cb, this));
  }
  MG_PETSC(TSSetRHSFunction(ts_, nullptr, rhsfunction_cb, this));
  MG_PETSC(TSSetSolution(ts_, X_));
  MG_PETSC(TSSetTime(ts_, 0.0));
  MG_PETSC(TSSetTimeStep(ts_, dt));
  MG_PETSC(TSSetMaxTime(ts_, dt));
  // The step count runs over the whole integration (TS's default cap is 5000 steps).
  MG_PETSC(TSSetMaxSteps(ts_, PETSC_MAX_INT));
  MG_PETSC(TSSetExactFinalTime(ts_, TS_EXACTFINALTIME_MATCHSTEP));
  // A failed step sets the converged reason (reported by step()) instead of raising an error.
  MG_PETSC(TSSetErrorIfStepFails(ts_, PETSC_FALSE));
  TSAdapt adapt;
  MG_PETSC(TSGetAdapt(ts_, &adapt));
  MG_PETSC(TSAdaptSetType(adapt, TSADAPTNONE));
  SNES snes;
  MG_PETSC(TSGetSNES(ts_, &snes));
  MG_PETSC(SNESSetType(snes, SNESKSPONLY));
  // A misspelt type or value is the user's: one line naming PETSc's complaint.
  const std::string err = petsc_quietly([&] { return TSSetFromOptions(ts_); });
  if (!err.empty())
    throw UserError("PETSc options of -integrator ts (-ts_*, -snes_*, -ksp_*, -pc_*): " + err);
  check_type();
  MG_PETSC(TSGetAdapt(ts_, &adapt));
  PetscBool none = PETSC_FALSE;
  MG_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(adapt), TSADAPTNONE, &none));
  adaptive_ = !none;
  next_dt_ = dt;
  if (ops_) setup_implicit_solver(dt);
}

// Explicit TS types cannot take the implicit diffusion; with explicit diffusion there is no
// implicit part, so implicit types are refused instead.
void TsIntegrator::check_type() {
  TSType type = nullptr;
  MG_PETSC(TSGetType(ts_, &type));
  const std::string tname = type ? type : "";
  bool explicit_type = false;
  for (const char* e : {TSEULER, TSRK, TSSSP, TSMPRK, TSBASICSYMPLECTIC, TSPSEUDO})
    explicit_type = explicit_type || tname == e;
  if (ops_ && explicit_type)
    throw UserError("-ts_type " + tname +
                    ": an explicit (or pseudo-transient) TS type cannot take the implicit "
                    "diffusion part; use arkimex (default), rosw, or an implicit type such as "
                    "bdf, cn, beuler or theta, or -ts_diffusion explicit");
  if (!ops_ && (!explicit_type || tname == TSPSEUDO))
    throw UserError("-ts_type " + tname +
                    ": with -ts_diffusion explicit every term is explicit; use an explicit type: "
                    "rk (default), euler or ssp");
}

// KSP (and SNES for fully implicit types) of the implicit diffusion part.
void TsIntegrator::setup_implicit_solver(double dt) {
  TSType type = nullptr;
  MG_PETSC(TSGetType(ts_, &type));
  const std::string tname = type ? type : "";
  SNES snes;
  KSP ksp;
  MG_PETSC(TSGetSNES(ts_, &snes));
  MG_PETSC(SNESGetKSP(snes, &ksp));
  bool symmetric = true;
  for (int s = 0; s < ops_->nspecies(); ++s)
    symmetric = symmetric && ops_->symmetric(s);
  // ksponly is exact only when the implicit part is the linear diffusion: IMEX schemes. Fully
  // implicit schemes also put the reaction into the solve, which then needs Newton (with the
  // diffusion Jacobian only, so it converges linearly at a rate ~ dt |dR/du|).
  PetscBool fully_implicit = PETSC_FALSE;
  if (tname == TSARKIMEX) MG_PETSC(TSARKIMEXGetFullyImplicit(ts_, &fully_implicit));
  const bool imex = (tname == TSARKIMEX && !fully_implicit) || tname == TSROSW || tname == TSEIMEX;
  PetscBool user_snes = PETSC_FALSE, user_ksp = PETSC_FALSE, user_pc = PETSC_FALSE;
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-snes_type", &user_snes));
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-ksp_type", &user_ksp));
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-pc_type", &user_pc));
  if (!imex && !user_snes) MG_PETSC(SNESSetType(snes, SNESNEWTONLS));
  MG_PETSC(fill_jacobian(1.0 / dt));
  jac_shift_ = -1; // force a refresh on the first call
  MG_PETSC(KSPSetOperators(ksp, J_, J_));
  const bool exact = try_exact_pc(ksp);
  if (!exact) iterative_defaults(ksp, symmetric, user_ksp, user_pc);
  // Set the linear solver up now, on an operator of the final pattern (set above; its values
  // are refreshed by the first IJacobian call), so that the parallel default (ICC blocks) can be
  // installed and every -ksp_/-pc_/-sub_ option is read before the caller checks for unused
  // options.
  const std::string err = petsc_quietly([&] { return KSPSetFromOptions(ksp); });
  if (!err.empty())
    throw UserError("PETSc options of the TS linear solver (-ksp_*, -pc_*): " + err);
  if (exact) {
    check_exact_kept(ksp);
    return;
  }
  if (symmetric)
    icc_subblocks(ksp, "-sub_pc_type");
  else
    set_up_or_refuse(ksp, "-");
}

// After KSPSetFromOptions: the exact inverse is still the solver (no option replaced it).
void TsIntegrator::check_exact_kept(KSP ksp) {
  KSPType kt = nullptr;
  PCType pt = nullptr;
  PC pc;
  MG_PETSC(KSPGetType(ksp, &kt));
  MG_PETSC(KSPGetPC(ksp, &pc));
  MG_PETSC(PCGetType(pc, &pt));
  if (std::string(kt) != KSPPREONLY || std::string(pt) != PCSHELL)
    throw UserError(std::string("-ts_diffusion_solver ") + solver_ +
                    ": the linear-solver options replaced the exact inverse (KSP " + kt + ", PC " +
                    pt + "); with them use -ts_diffusion_solver ksp");
}

// The iterative solve's defaults (CG + ICC, or GMRES + ILU for a non-symmetric operator;
// block Jacobi in parallel; rtol 1e-10), each unless the user gave it.
void TsIntegrator::iterative_defaults(KSP ksp, bool symmetric, bool user_ksp, bool user_pc) {
  int size = 1;
  MPI_Comm_size(grid_.comm(), &size);
  PC pc;
  MG_PETSC(KSPGetPC(ksp, &pc));
  if (symmetric) {
    if (!user_ksp) MG_PETSC(KSPSetType(ksp, KSPCG));
    if (!user_pc) MG_PETSC(PCSetType(pc, size == 1 ? PCICC : PCBJACOBI));
  } else { // first-order tensor masks: a non-symmetric operator
    if (!user_ksp) MG_PETSC(KSPSetType(ksp, KSPGMRES));
    if (!user_pc) MG_PETSC(PCSetType(pc, size == 1 ? PCILU : PCBJACOBI));
  }
  PetscBool user_rtol = PETSC_FALSE;
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-ksp_rtol", &user_rtol));
  if (!user_rtol) MG_PETSC(KSPSetTolerances(ksp, 1e-10, PETSC_DEFAULT, PETSC_DEFAULT, 10000));
}

// Why the exact preconditioner cannot serve this run ("" when it can): -ts_diffusion_solver
// ksp, a linear-solver option that asks for another method (or a nonzero initial guess, which
// preonly refuses), a matrix-free Jacobian (-snes_mf: the IJacobian, and with it the shift,
// never comes), or coefficients that change the matrices during the run.
std::string TsIntegrator::exact_pc_blocker() const {
  if (solver_ == "ksp") return "-ts_diffusion_solver ksp";
  for (const char* name : {"-ksp_type", "-pc_type", "-sub_pc_type", "-ksp_rtol", "-ksp_atol",
                           "-ksp_max_it", "-ksp_initial_guess_nonzero", "-snes_mf"}) {
    PetscBool set = PETSC_FALSE;
    MG_PETSC(PetscOptionsHasName(nullptr, nullptr, name, &set));
    if (set) return std::string(name) + " was given";
  }
  if (terms_.any_timed_coefficients()) return "coefficients follow t";
  if (terms_.any_state_dependent()) return "coefficients follow the state";
  return "";
}

bool TsIntegrator::try_exact_pc(KSP ksp) {
  std::string why = exact_pc_blocker();
  std::vector<std::unique_ptr<ExactSolve>> solves(static_cast<size_t>(ns_));
  std::vector<double> scale(static_cast<size_t>(ns_));
  for (int s = 0; s < ns_ && why.empty(); ++s) {
    scale[s] = ops_->scale(s);
    if (scale[s] == 0.0) continue;
    std::string w = "a non-symmetric operator";
    if (ops_->symmetric(s)) solves[s] = auto_exact_solve(grid_, ops_->M(s), &w);
    if (!solves[s]) why = "species " + species_[s] + ": " + w;
  }
  if (!why.empty()) {
    if (solver_ == "spectral")
      throw UserError("-ts_diffusion_solver spectral: " + why + "; allowed here: ksp or auto");
    PetscPrintf(grid_.comm(), "  TS diffusion solve: ksp (%s)\n", why.c_str());
    return false;
  }
  exact_pc_ =
      std::make_unique<TsExactPc>(grid_, std::move(solves), scale, &pc_shift_, &callback_error_);
  exact_pc_->install(ksp);
  for (int s = 0; s < ns_; ++s)
    PetscPrintf(grid_.comm(), "  TS diffusion solve of %s: %s, the exact inverse (preonly)\n",
                species_[s].c_str(), exact_pc_->method(s).c_str());
  return true;
}

// ---- PETSc callbacks: no exception may leave them -------------------------------------------

void TsIntegrator::at_time(double t) {
  if (!timed_ || !terms_.set_time(t) || !ops_) return;
  MG_PETSC(MatZeroEntries(Dblock_)); // (the pattern stays: OperatorMatrices::keep_pattern)
  fill_operator();
  jac_shift_ = -1; // J = shift I - K refilled on the next IJacobian
}

PetscErrorCode TsIntegrator::ifunction_cb(TS, PetscReal t, Vec X, Vec Xdot, Vec F, void* ctx) {
  auto* self = static_cast<TsIntegrator*>(ctx);
  try {
    self->at_time(t);
    return self->ifunction(X, Xdot, F);
  } catch (...) {
    self->callback_error_ = std::current_exception();
    return PETSC_ERR_LIB;
  }
}

PetscErrorCode TsIntegrator::rhsfunction_cb(TS, PetscReal t, Vec X, Vec G, void* ctx) {
  auto* self = static_cast<TsIntegrator*>(ctx);
  try {
    self->at_time(t);
    return self->rhsfunction(t, X, G);
  } catch (...) {
    self->callback_error_ = std::current_exception();
    return PETSC_ERR_LIB;
  }
}

PetscErrorCode TsIntegrator::ijacobian_cb(TS, PetscReal t, Vec, Vec, PetscReal shift, Mat A, Mat P,
                                          void* ctx) {
  auto* self = static_cast<TsIntegrator*>(ctx);
  try {
    self->at_time(t);
    return self->ijacobian(shift, A, P);
  } catch (...) {
    self->callback_error_ = std::current_exception();
    return PETSC_ERR_LIB;
  }
}

// F(t, X, Xdot) = Xdot - (blockdiag(D_s L) X + D_s b_s)
PetscErrorCode TsIntegrator::ifunction(Vec X, Vec Xdot, Vec F) {
  PetscFunctionBeginUser;
  PetscCall(MatMult(Dblock_, X, F));
  PetscCall(VecAYPX(F, -1.0, Xdot));
  if (has_b_) PetscCall(VecAXPY(F, -1.0, bD_));
  PetscFunctionReturn(0);
}

// G(t, X) = the sum of the right-hand-side terms, on a ghosted local copy of X.
PetscErrorCode TsIntegrator::rhsfunction(PetscReal t, Vec X, Vec G) {
  PetscFunctionBeginUser;
  Vec Xl = nullptr;
  PetscCall(DMGetLocalVector(dm_, &Xl));
  PetscCall(DMGlobalToLocalBegin(dm_, X, INSERT_VALUES, Xl));
  PetscCall(DMGlobalToLocalEnd(dm_, X, INSERT_VALUES, Xl));
  PetscScalar* xl = nullptr;
  PetscScalar* g = nullptr;
  PetscCall(VecGetArray(Xl, &xl));
  PetscCall(VecGetArray(G, &g));
  PetscCall(PetscArrayzero(g, ns_ * nloc_));
  std::exception_ptr error;
  try {
    add_rhs_terms(xl, t, g);
  } catch (...) { // arrays go back to PETSc before the error is reported
    error = std::current_exception();
  }
  PetscCall(VecRestoreArray(G, &g));
  PetscCall(VecRestoreArray(Xl, &xl));
  PetscCall(DMRestoreLocalVector(dm_, &Xl));
  if (error) std::rethrow_exception(error); // recorded by the callback wrapper
  PetscFunctionReturn(0);
}

void TsIntegrator::add_rhs_terms(const PetscScalar* xl, double t, PetscScalar* g) const {
  StateArrays state;
  RateArrays rates;
  state.stride = rates.stride = ns_;
  for (PetscInt s = 0; s < ns_; ++s) {
    state.u.push_back(xl + s);
    rates.r.push_back(g + s);
  }
  if (rhs_halo_.width > 0) // ghosts outside non-periodic faces (the local copy is ours)
    for (PetscInt s = 0; s < ns_; ++s)
      halo_.fill_boundaries(
          const_cast<double*>(xl) + s,
          dirichlet_ && !dirichlet_->empty() ? &(*dirichlet_)[static_cast<size_t>(s)] : nullptr,
          ns_);
  for (const Term* term : rhs_)
    term->add_rates(state, t, rates);
  if (const PinnedCells* pins = terms_.pins()) // held cells do not move
    for (int s = 0; s < pins->nspecies(); ++s)
      for (const PinnedCells::Cell& c : pins->cells(s))
        g[ns_ * c.owned + s] = 0.0;
}

// J = shift I - blockdiag(D_s L), refreshed only when the shift changed.
PetscErrorCode TsIntegrator::fill_jacobian(PetscReal shift) {
  PetscFunctionBeginUser;
  PetscCall(MatCopy(Dblock_, J_, SAME_NONZERO_PATTERN));
  PetscCall(MatScale(J_, -1.0));
  PetscCall(MatShift(J_, shift));
  jac_shift_ = shift;
  PetscFunctionReturn(0);
}

PetscErrorCode TsIntegrator::ijacobian(PetscReal shift, Mat A, Mat P) {
  PetscFunctionBeginUser;
  PetscCheck(P == J_, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
             "TsIntegrator: unexpected preconditioning matrix");
  // Only this class writes J (no RHS Jacobian is registered, so TS never adds to it).
  if (shift != jac_shift_) PetscCall(fill_jacobian(shift));
  pc_shift_ = shift; // the exact preconditioner inverts this J (also when J is lagged)
  if (A != P) {
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  }
  PetscFunctionReturn(0);
}

// ---- stepping -------------------------------------------------------------------------------

bool TsIntegrator::copy_state(std::vector<VecH>& u, bool to_x) {
  const Box& ob = grid_.owned();
  bool changed = false;
  PetscScalar* x = nullptr;
  MG_PETSC(VecGetArray(X_, &x));
  for (PetscInt s = 0; s < ns_; ++s) {
    PetscScalar* l = nullptr;
    MG_PETSC(VecGetArray(u[static_cast<size_t>(s)], &l));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
        double* lr = l + grid_.local_index(ob.s[0], j, k);
        double* xr = x + ns_ * grid_.owned_index(ob.s[0], j, k) + s;
        for (PetscInt i = 0; i < ob.m[0]; ++i) {
          if (to_x) {
            changed = changed || xr[ns_ * i] != lr[i];
            xr[ns_ * i] = lr[i];
          } else {
            lr[i] = xr[ns_ * i];
          }
        }
      }
    MG_PETSC(VecRestoreArray(u[static_cast<size_t>(s)], &l));
  }
  MG_PETSC(VecRestoreArray(X_, &x));
  return changed;
}

void TsIntegrator::step(std::vector<VecH>& u, double t, double dt, PetscInt step) {
  if (static_cast<PetscInt>(u.size()) != ns_)
    throw std::logic_error("TsIntegrator::step: wrong number of species vectors");
  // Solution-dependent diffusion: coefficients of u^n, lagged over the step (the implicit
  // operator and its Jacobian rebuilt from the re-assembled matrices).
  if (!terms_.refresh(u).empty() && ops_) {
    build_operator();
    MG_PETSC(TSSetIJacobian(ts_, J_, J_, ijacobian_cb, this));
    jac_shift_ = -1;
  }
  // TS continues from its last solve (multistep schemes such as -ts_type bdf keep their
  // history) unless the state or the time changed in between (the clamp floor, a restart):
  // then it restarts the step, without reusing stage or history data.
  PetscReal tprev = 0;
  MG_PETSC(TSGetTime(ts_, &tprev));
  // (Callers compute t as step * dt or by summation: allow for rounding.)
  const bool moved = std::abs(tprev - t) > 1e-10 * std::max(std::abs(t), std::abs(dt));
  int restart = copy_state(u, true) || moved;
  MPI_Allreduce(MPI_IN_PLACE, &restart, 1, MPI_INT, MPI_LOR, grid_.comm());
  if (restart && solved_) MG_PETSC(TSRestartStep(ts_));
  solved_ = true;
  const double tend = t + dt;
  const double h0 = adaptive_ ? std::min(next_dt_, dt) : dt;
  MG_PETSC(TSSetTime(ts_, t));
  MG_PETSC(TSSetMaxTime(ts_, tend));
  MG_PETSC(TSSetTimeStep(ts_, h0));
  callback_error_ = nullptr;
  PetscErrorCode ierr = 0;
  {
    QuietPetscErrors quiet;
    ierr = TSSolve(ts_, X_);
  }
  auto where = [&] {
    std::ostringstream m;
    m.precision(10);
    m << "step " << step << " (t = " << t << ", dt = " << dt << ")";
    return m.str();
  };
  if (ierr) {
    // A callback's own exception goes on; a UserError (from a source expression, say) with
    // the step added.
    if (callback_error_) {
      const std::exception_ptr e = std::exchange(callback_error_, nullptr);
      try {
        std::rethrow_exception(e);
      } catch (const UserError& ue) {
        throw UserError(std::string(ue.what()) + " (in the TS solve of " + where() + ")");
      }
    }
    const char* text = nullptr;
    char* specific = nullptr;
    PetscErrorMessage(ierr, &text, &specific);
    std::fprintf(stderr, "morphogen: PETSc error in the TS solve at %s: %s%s%s\n", where().c_str(),
                 text ? text : "error", specific && *specific ? ": " : "",
                 specific ? specific : "");
    throw PetscFailure(ierr);
  }
  TSConvergedReason reason;
  MG_PETSC(TSGetConvergedReason(ts_, &reason));
  // Both counters run over all solves (TS resets them only while its step number is 0).
  const PetscInt before = steps_;
  MG_PETSC(TSGetStepNumber(ts_, &steps_));
  MG_PETSC(TSGetStepRejections(ts_, &rejected_));
  const PetscInt n = steps_ - before;
  PetscReal treached = t;
  MG_PETSC(TSGetTime(ts_, &treached));
  if (reason < 0) {
    SNES snes;
    KSP ksp;
    SNESConvergedReason sreason;
    KSPConvergedReason kreason;
    MG_PETSC(TSGetSNES(ts_, &snes));
    MG_PETSC(SNESGetConvergedReason(snes, &sreason));
    MG_PETSC(SNESGetKSP(snes, &ksp));
    MG_PETSC(KSPGetConvergedReason(ksp, &kreason));
    PetscInt kits = 0;
    MG_PETSC(KSPGetIterationNumber(ksp, &kits));
    std::ostringstream m;
    m.precision(10);
    m << "TS integrator diverged at " << where() << ", internal time " << treached << ": TS "
      << TSConvergedReasons[reason] << ", SNES " << SNESConvergedReasons[sreason] << ", KSP "
      << KSPConvergedReasons[kreason] << " after " << kits
      << " iterations; try a smaller -dt, -ts_adapt_type basic, or other -ksp_type / -pc_type";
    throw UserError(m.str());
  }
  if (!(std::abs(treached - tend) <= 1e-12 * std::max(std::abs(tend), std::abs(dt)))) {
    std::ostringstream m;
    m.precision(17);
    m << "TS integrator stopped at t = " << treached << " short of " << tend << " in " << where()
      << " after " << n << " internal steps (TS " << TSConvergedReasons[reason]
      << "); raise -ts_max_steps or loosen -ts_rtol/-ts_atol";
    throw UserError(m.str());
  }
  if (adaptive_) {
    PetscReal h = dt;
    MG_PETSC(TSGetTimeStep(ts_, &h));
    if (h > 0 && std::isfinite(h)) next_dt_ = h;
  }
  copy_state(u, false);
  terms_.constrain(u);
}

} // namespace morphogen
