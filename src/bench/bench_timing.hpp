// Timing of a run's steps for morphogen-bench: the best over `reps` blocks of `steps` steps, in
// seconds per step, every block started and ended by a barrier (the slowest rank counts).
#pragma once

#include "app/simulation.hpp"

#include <algorithm>

namespace morphogen {

inline double best_seconds_per_step(MPI_Comm comm, Simulation& sim, int steps, int reps) {
  double best = 1e30;
  for (int rep = 0; rep < reps; ++rep) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    for (int i = 0; i < steps; ++i)
      sim.step();
    MPI_Barrier(comm);
    best = std::min(best, (MPI_Wtime() - t0) / steps);
  }
  return best;
}

} // namespace morphogen
