// `morphogen screen [DECK.yaml] [-option value ...]`: a Turing screen, the linear stability of
// many parameter sets of any model (registered, layered or custom) without simulating them.
// Each set i (sweep/screen_sampling.hpp: grid, random or Latin hypercube over the ranges of
// -screen_params) is classified at its homogeneous steady state (sweep/screen_classify.hpp:
// no steady state / unstable at k = 0 / stable / Turing-unstable, with the fastest wavelength
// and growth rate); options in sweep/screen_spec.hpp. A deck is a model deck plus a `screen:`
// section (screen: {params: alpha,beta, range_alpha: "1,5", ...}); its other keys (grid, init,
// dt, ...) are allowed and unused, but every screen_*, params_* and D_* key must be read.
//
// Parallel: the sets are cut into chunks of >= 4096 consecutive indices, dealt to the ranks
// round-robin (chunk c to rank c mod P); the results do not depend on the rank count.
// Output (sweep/screen_output.hpp) in -screen_output DIR: turing_sets.csv (the Turing-unstable
// sets, index order) and screen.json (setup, counts, wall time, sets/s, ranks); one summary
// line on stdout, and a progress line every 10 s on long screens.
// Exit codes: 0, 1 bad input (one line, nothing written), 4 an output file failed.
#pragma once

#include "app/deck.hpp"

#include <vector>

namespace morphogen::sweep {

// Returns the exit code. argv[1] is "screen"; argv[2], unless it starts with '-', the deck.
int run_screen(int* argc, char*** argv, const std::vector<OptionsFileArg>& options_files = {});

} // namespace morphogen::sweep
