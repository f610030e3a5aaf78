// The exit code as the ranks see it, for job scripts: a launcher may not pass it on (Open MPI's
// mpiexec returns 1 when SIGTERM reached it and the ranks checkpointed and exited 3). With
// MORPHOGEN_EXIT_FILE=PATH in the environment, rank 0 writes the code (one line) to PATH on the
// way out (written to PATH.tmp and renamed). Aborted runs (exit 2, 4) write nothing.
#pragma once

namespace morphogen {

// Call on every rank before PetscFinalize; only rank 0 writes.
void write_exit_file(int rc);

} // namespace morphogen
