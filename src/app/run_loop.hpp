// The time loop of a configured Simulation: steps up to a global step index, progress lines
// (step, time, cell-updates per second, ETA), the NaN/Inf guard (naming the last good
// checkpoint), snapshots and checkpoints through RunOutput, PNG quick-looks every -png_every
// steps and at the end.
#pragma once

#include "app/png_output.hpp"
#include "app/run_output.hpp"
#include "app/simulation.hpp"

namespace morphogen {

// Steps until sim.step_index() == end_step. Returns false when it got there, true when it
// stopped early with a checkpoint (signal or wall-time budget; see output.stop_reason()).
// final_level: write the final images, snapshot and checkpoint at the end. pngs writes the
// PNG quick-looks (every -png_every steps and at the end).
bool run_loop(Simulation& sim, PetscInt end_step, RunOutput& output, PngOutput& pngs,
              bool final_level);

} // namespace morphogen
