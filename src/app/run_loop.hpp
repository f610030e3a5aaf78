// The time loop of a configured Simulation: steps, progress lines (step, time, cell-updates per
// second, ETA), the NaN/Inf guard, PNG quick-looks every -png_every steps and at the end.
#pragma once

#include "app/simulation.hpp"

namespace morphogen {

// Writes PNG images of the selected species at the current step into the output directory.
void write_pngs(Simulation& sim, const std::string& tag);

void run_loop(Simulation& sim);

} // namespace morphogen
