// Options of the advection stage (operators/advection_stage.hpp):
//   -advect a,b                       species carried by the velocity (default: none)
//   -advection_scheme linear|cubic    interpolation at the departure point (default linear)
//   -advection_backtrace rk2|euler    departure point: midpoint rule (default) or the paper's
//                                     eq. 20 (one Euler step back)
//   -advection_halo W                 halo width in cells (default: sized from max|u| dt / h)
//   -velocity_x/_y/_z EXPR            the velocity (fields/velocity_field.hpp), or
//   -velocity_file F [-velocity_datasets X,Y]  the velocity from HDF5 files
//                                     (fields/velocity_file.hpp; refused beside -velocity_x or
//                                     -fluid)
// Without -advect the other options are refused with a one-line UserError.
#pragma once

#include "operators/advection_stage.hpp"

namespace morphogen {

// The run's advection stage, or null when -advect is not given. With `fluid` (the run's
// stable-fluids solver, -fluid) the velocity is the fluid's and -velocity_* are refused.
// Collective.
std::unique_ptr<AdvectionStage> read_advection(Options& opt, const Grid& grid,
                                               const std::vector<std::string>& species,
                                               std::uint64_t seed, const std::string& base_dir,
                                               double dt, const VelocitySource* fluid = nullptr);

} // namespace morphogen
