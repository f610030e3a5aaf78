#include "integrators/ksp_defaults.hpp"

#include "core/options.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <string>

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
  const std::string sub = sub_pc_option;
  set_up_or_refuse(ksp, sub.substr(0, sub.size() - std::string("sub_pc_type").size()));
}

void set_up_or_refuse(KSP ksp, const std::string& prefix) {
  const std::string err = petsc_quietly([&] { return KSPSetUp(ksp); });
  if (err.empty()) return;
  const std::string named = name_petsc_option_error(prefix.substr(1), err);
  throw UserError(
      !named.empty()
          ? named
          : prefix + "ksp_*/" + prefix +
                "pc_* options: PETSc could not set the solver up with them (" + one_line(err) +
                ")" +
                (err.find("KSPSetDM") != std::string::npos
                     ? "; with " + prefix + "pc_type mg add " + prefix + "pc_mg_galerkin both"
                     : ""));
}

} // namespace morphogen
