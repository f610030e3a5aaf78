// morphogen's default linear solver for its SPD diffusion systems: CG with incomplete Cholesky
// on one rank, CG with block Jacobi and ICC blocks in parallel (PETSc's ICC is sequential).
// set_cg_icc() sets the types before KSPSetFromOptions (so options override them);
// icc_subblocks() sets the solver up with ICC in the block-Jacobi blocks, unless the user gave
// the sub-PC option named `sub_pc_option` (e.g. "-diffusion_sub_pc_type").
// set_up_or_refuse() runs KSPSetUp; a PETSc refusal (e.g. -diffusion_pc_type mg without
// -diffusion_pc_mg_galerkin) becomes a one-line UserError naming the options under `prefix`
// ("-diffusion_", "-").
#pragma once

#include <petscksp.h>

#include <string>

namespace morphogen {

void set_cg_icc(KSP ksp);
void icc_subblocks(KSP ksp, const char* sub_pc_option);
void set_up_or_refuse(KSP ksp, const std::string& prefix);

} // namespace morphogen
