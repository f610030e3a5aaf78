// The stable-fluids section of morphogen-bench (-bench_fluids true): frames per second of the
// 2-D fluid solver alone and of the fluid plus implicit advection-reaction-diffusion (Gray-Scott,
// split integrator, both species advected) on a lid-driven cavity at 128^2 .. 1024^2, beside the
// stable-ARD paper's Table 1 (Cell processor: 223, 78.5, 21.5, 5.5 fps with RD), with the time
// per frame split into fluid solve / advection / RD.
#pragma once

#include "core/options.hpp"

namespace morphogen {

void bench_fluids(MPI_Comm comm, Options& opt, int max_n, int steps);

} // namespace morphogen
