#include "integrators/ksp_defaults.hpp"

#include "core/petsc_handle.hpp"

namespace morphogen {

void set_cg_icc(KSP ksp) {
  int size = 1;
  MPI_Comm_size(PetscObjectComm(reinterpret_cast<PetscObject>(ksp)), &size);
  MG_PETSC(KSPSetType(ksp, KSPCG));
  PC pc;
  MG_PETSC(KSPGetPC(ksp, &pc));
  MG_PETSC(PCSetType(pc, size == 1 ? PCICC : PCBJACOBI));
}

void icc_subblocks(KSP ksp, const char* sub_pc_option) {
  PC pc;
  MG_PETSC(KSPGetPC(ksp, &pc));
  PetscBool bj = PETSC_FALSE, user_sub = PETSC_FALSE;
  MG_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCBJACOBI, &bj));
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, sub_pc_option, &user_sub));
  // The default goes into the options database, so that the blocks read it together with the
  // user's other sub-solver options (e.g. -sub_pc_factor_levels) when they are set up.
  if (bj && !user_sub) MG_PETSC(PetscOptionsSetValue(nullptr, sub_pc_option, "icc"));
  MG_PETSC(KSPSetUp(ksp));
}

} // namespace morphogen
