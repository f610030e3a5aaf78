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
  MG_PETSC(KSPSetUp(ksp));
  if (!bj || user_sub) return;
  PetscInt nblocks = 0, first = 0;
  KSP* sub = nullptr;
  MG_PETSC(PCBJacobiGetSubKSP(pc, &nblocks, &first, &sub));
  for (PetscInt q = 0; q < nblocks; ++q) {
    PC spc;
    MG_PETSC(KSPGetPC(sub[q], &spc));
    MG_PETSC(PCSetType(spc, PCICC));
  }
}

} // namespace morphogen
