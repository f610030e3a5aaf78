// Range checks of PETSc solver options that PETSc itself takes unchecked (KSPSetFromOptions
// assigns -ksp_rtol 2 or nan as given: every solve then "converges" at once) or that crash it
// (-pc_mg_levels 0). Any prefix: -diffusion_ksp_rtol, -fluid_ksp_rtol, -ksp_rtol, ...
//   *ksp_rtol [0, 1)    *ksp_atol, *ts_rtol, *ts_atol, *snes_rtol, *snes_atol, *snes_stol >= 0
//   *ksp_divtol > 0     *ksp_max_it, *snes_max_it >= 0    *pc_mg_levels >= 1
// (all finite). A value that is not a number is left to PETSc, which names it. The options are
// read from the database as text, so they are not marked used (an option of a solver this run
// does not have is still reported as unknown).
#pragma once

namespace morphogen {

// Throws UserError "-NAME VALUE: out of range, allowed ..." for the first bad value.
void check_solver_option_values();

} // namespace morphogen
