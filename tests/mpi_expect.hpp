// Helpers that reduce a test verdict across all ranks of PETSC_COMM_WORLD, so a failure on
// rank 1 fails the test on every rank (and is reported by rank 0).
#pragma once

#include <mpi.h>
#include <petscsys.h>

namespace morphogen::testing {

inline bool all_ranks(bool ok) {
  int local = ok ? 1 : 0, global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
  return global == 1;
}

inline double max_over_ranks(double v) {
  double g = 0;
  MPI_Allreduce(&v, &g, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
  return g;
}

inline int comm_size() {
  int n = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &n);
  return n;
}

} // namespace morphogen::testing
