// `morphogen [DECK.yaml] [-option value ...]`: one run (the entry point is cli/main.cpp).
//
// Loads the deck (or the embedded default, Sanderson Fig. 1) into PETSc's options database,
// overrides it with the command line, validates every option (unknown options fail with a
// "did you mean"), writes options_used.yaml and runs, writing snapshots and checkpoints.
#pragma once

#include "app/deck.hpp"

#include <vector>

namespace morphogen {

// Called after PetscInitialize; wall_start (MPI_Wtime) is when -max_walltime starts counting.
// Returns the exit code: 0 success, kExitResubmit (3) stopped by a signal or -max_walltime after
// writing a checkpoint. Bad input throws UserError, a PETSc error PetscFailure.
// With help requested (Options::help_requested) it prints the options and models and returns 0
// without writing anything. options_files: -options_file arguments (app/command_line.hpp).
int run_main(int* argc, char*** argv, double wall_start,
             const std::vector<OptionsFileArg>& options_files = {});

} // namespace morphogen
