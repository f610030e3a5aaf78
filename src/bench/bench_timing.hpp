// Timing of a run's steps for morphogen-bench: the best over `reps` blocks of `steps` steps, in
// seconds per step, every block started and ended by a barrier (the slowest rank counts).
// interleaved_best times two runs block by block in turn (a, b, a, b, ...), so that a slow phase
// of a shared machine slows both sides of a ratio rather than one; each timed block follows an
// untimed step of its run (the other run has just had the caches).
#pragma once

#include "app/simulation.hpp"

#include <algorithm>
#include <functional>
#include <utility>

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

// A run's timed block (`steps` steps) and the untimed step before it.
struct TimedBlock {
  std::function<void()> warm, block;
  int steps = 1;
};

// Seconds per step of the best block of each run, `reps` blocks each.
inline std::pair<double, double> interleaved_best(MPI_Comm comm, const TimedBlock& a,
                                                  const TimedBlock& b, int reps) {
  std::pair<double, double> best{1e30, 1e30};
  auto time = [&](const TimedBlock& r, double& t) {
    r.warm();
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    r.block();
    MPI_Barrier(comm);
    t = std::min(t, (MPI_Wtime() - t0) / r.steps);
  };
  for (int rep = 0; rep < reps; ++rep) {
    time(a, best.first);
    time(b, best.second);
  }
  return best;
}

} // namespace morphogen
