// `morphogen sweep DECK.yaml [-option value ...]`: a phase-diagram sweep. The deck is a base
// run plus a `sweep:` section (see sweep_spec.hpp); every point is run, measured and classified
// (point_runner.hpp) on a group of -sweep_group_size ranks, points are handed out dynamically
// (work_queue.hpp), and the results go to -output_dir:
//   points/point_<i>.vtkhdf, points/point_<i>.json   per point (fields; record + time series)
//   sweep.csv, sweep.json                            the table of every finished point
// Finished points are skipped when the sweep is run again (a killed sweep resumes), and
// -sweep_chunk c -sweep_chunks C runs only the points p with p mod C == c (job arrays).
// SIGUSR1/SIGTERM: the running points are abandoned, the table written, exit code 3.
#pragma once

#include "app/deck.hpp"

#include <vector>

namespace morphogen::sweep {

// Returns the exit code. argv[1] is "sweep" and argv[2] the deck (which must have a sweep:
// section). options_files: -options_file arguments (app/command_line.hpp).
int run_sweep(int* argc, char*** argv, const std::vector<OptionsFileArg>& options_files = {});

} // namespace morphogen::sweep
