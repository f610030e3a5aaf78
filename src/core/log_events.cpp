#include "core/log_events.hpp"

#include "core/petsc_handle.hpp"

namespace morphogen {

const LogEvents& log_events() {
  static const LogEvents ev = [] {
    LogEvents e{};
    PetscClassId cid;
    MG_PETSC(PetscClassIdRegister("morphogen", &cid));
    MG_PETSC(PetscLogEventRegister("MgHalo", cid, &e.halo));
    MG_PETSC(PetscLogEventRegister("MgExplicitSweep", cid, &e.sweep));
    MG_PETSC(PetscLogEventRegister("MgSetup", cid, &e.setup));
    MG_PETSC(PetscLogEventRegister("MgOutput", cid, &e.output));
    MG_PETSC(PetscLogEventRegister("MgReaction", cid, &e.reaction));
    MG_PETSC(PetscLogEventRegister("MgDiffusion", cid, &e.diffusion));
    return e;
  }();
  return ev;
}

} // namespace morphogen
