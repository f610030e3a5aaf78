// Options of the stable-fluids solver (operators/fluid_solver.hpp):
//   -fluid none|cavity|channel|periodic   the flow (default none: no fluid)
//   -fluid_viscosity NU                   kinematic viscosity (default 0.01; 0: inviscid)
//   -fluid_lid_speed U                    cavity: speed of the top wall (default 1)
//   -fluid_inflow U                       channel: inflow speed on the left (default 1)
//   -fluid_obstacle EXPR                  solid where the value > 0.5 (default 0: none)
//   -fluid_substeps N                     fluid substeps per run step (default 1)
//   -fluid_scheme linear|cubic            self-advection interpolation (default linear)
//   -fluid_ksp_* / -fluid_pc_*            the pressure solve (default CG with GAMG)
//   -fluid_visc_ksp_* / -fluid_visc_pc_*  the viscosity solves (default CG with Jacobi)
// Without -fluid (or with none) the other options are refused with a one-line UserError; a
// 3-D grid is refused.
#pragma once

#include "core/options.hpp"
#include "operators/fluid_solver.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace morphogen {

// The run's fluid solver, or null without -fluid. Collective.
std::unique_ptr<FluidSolver> read_fluid(Options& opt, const Grid& grid, std::uint64_t seed,
                                        const std::string& base_dir);

} // namespace morphogen
