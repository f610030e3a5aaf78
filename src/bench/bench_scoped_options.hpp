// Options of one integrator given on the bench's command line. morphogen refuses them in a run
// of another integrator (-explicit_in_place, -explicit_vector_width, -explicit_fuse_tile,
// -explicit_fuse_steps, -explicit_prefetch belong to explicit runs; -ts_diffusion,
// -ts_diffusion_solver to TS runs), and the bench times runs of every integrator: they are held
// back when the bench starts (hold_integrator_options) and, where given, set before each run only
// when the run's -integrator (from the options database, default explicit) is theirs and cleared
// otherwise (apply_integrator_options, called before every Simulation of the bench; the fused
// section sets its own -explicit_fuse_steps after it).
#pragma once

namespace morphogen {

void hold_integrator_options();
void apply_integrator_options();

} // namespace morphogen
