#include "integrators/ts_exact_pc.hpp"

#include <stdexcept>

namespace morphogen {

TsExactPc::TsExactPc(const Grid& grid, std::vector<std::unique_ptr<ExactSolve>> solves,
                     std::vector<double> scale, const PetscReal* shift, std::exception_ptr* error)
    : solves_(std::move(solves)), scale_(std::move(scale)), shift_(shift), error_(error) {
  ns_ = static_cast<PetscInt>(solves_.size());
  if (static_cast<PetscInt>(scale_.size()) != ns_)
    throw std::logic_error("TsExactPc: one scale per species");
  for (PetscInt s = 0; s < ns_; ++s)
    if (!solves_[s] && scale_[s] != 0.0)
      throw std::logic_error("TsExactPc: a diffusing species without an exact solve");
  nloc_ = grid.owned().size();
  rs_ = grid.create_global();
  zs_ = grid.create_global();
}

void TsExactPc::install(KSP ksp) {
  PC pc;
  MG_PETSC(KSPSetType(ksp, KSPPREONLY));
  MG_PETSC(KSPGetPC(ksp, &pc));
  MG_PETSC(PCSetType(pc, PCSHELL));
  MG_PETSC(PCShellSetContext(pc, this));
  MG_PETSC(PCShellSetApply(pc, apply_cb));
  MG_PETSC(PCShellSetName(pc, "morphogen exact diffusion inverse (FFT/DCT, tridiagonal)"));
}

std::string TsExactPc::method(int s) const {
  return solves_[s] ? solves_[s]->method() : "none needed (no diffusion)";
}

PetscErrorCode TsExactPc::apply_cb(PC pc, Vec r, Vec z) {
  PetscFunctionBeginUser;
  void* ctx = nullptr;
  PetscCall(PCShellGetContext(pc, &ctx));
  auto* self = static_cast<TsExactPc*>(ctx);
  try {
    self->apply(r, z);
  } catch (const PetscFailure& e) { // PETSc has printed its trace
    return e.code;
  } catch (...) { // kept for the integrator (no exception may cross PETSc's C code)
    if (self->error_) *self->error_ = std::current_exception();
    return PETSC_ERR_LIB;
  }
  PetscFunctionReturn(0);
}

// z = J^-1 r, species by species: de-interlace r_s, solve, re-interlace z_s.
void TsExactPc::apply(Vec r, Vec z) {
  const double shift = *shift_;
  if (!(shift > 0.0)) throw std::logic_error("TsExactPc: no IJacobian shift yet");
  PetscInt n = 0;
  MG_PETSC(VecGetLocalSize(r, &n));
  if (n != ns_ * nloc_) throw std::logic_error("TsExactPc: not the interlaced state's layout");
  const PetscScalar* ra = nullptr;
  PetscScalar* za = nullptr;
  MG_PETSC(VecGetArrayRead(r, &ra));
  MG_PETSC(VecGetArray(z, &za));
  for (PetscInt s = 0; s < ns_; ++s) {
    PetscScalar* x = nullptr;
    MG_PETSC(VecGetArray(rs_, &x));
    for (PetscInt c = 0; c < nloc_; ++c)
      x[c] = ra[ns_ * c + s];
    MG_PETSC(VecRestoreArray(rs_, &x));
    if (solves_[s]) solves_[s]->solve_shifted(rs_, zs_, scale_[s] / shift, 1.0);
    const PetscScalar* y = nullptr;
    MG_PETSC(VecGetArrayRead(solves_[s] ? zs_.get() : rs_.get(), &y));
    for (PetscInt c = 0; c < nloc_; ++c)
      za[ns_ * c + s] = y[c] / shift;
    MG_PETSC(VecRestoreArrayRead(solves_[s] ? zs_.get() : rs_.get(), &y));
  }
  MG_PETSC(VecRestoreArray(z, &za));
  MG_PETSC(VecRestoreArrayRead(r, &ra));
}

} // namespace morphogen
