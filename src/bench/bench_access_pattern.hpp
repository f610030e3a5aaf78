// The access-pattern section of morphogen-bench (-bench_access_rows, -bench_access_3d_n; issue 13
// part 2): the memory side of an explicit step without its arithmetic. In 2-D: Two species of R
// rows x 4096 cells per rank (ghosted rows of 4098, as the grid's), each pattern swept once per
// repetition with the cheapest arithmetic that keeps its loads and stores (u <- u + 0.1 (sum of
// taps - n u)):
//   in_place_pointwise   u(i) from u(i) only, written back in place (one read, one write stream)
//   in_place_save_old    the same, also storing the old row into a two-row buffer
//   ring_pointwise       the same through a row ring: new row into the ring, copied back
//   ring_pointwise_stream  the same, the ring's rows copied back by streaming stores
//   ring_xtaps           taps i - 1, i, i + 1 of the row, through the ring
//   ring_5pt             5-point taps (rows j - 1, j, j + 1), the ring one row behind (the in-place
//                        sweep of the explicit fast path)
//   ring_5pt_prefetch    the same with the fast path's prefetch (the row two past the leading
//                        row, before each row)
//   ring_5pt_stream, ring_5pt_prefetch_stream  ring_5pt and ring_5pt_prefetch with the ring's
//                        rows copied back by streaming stores (bench_stream_copy.hpp)
//   out_of_place_5pt     5-point taps into a second state set
// printed as ns per cell and rank, aggregate cell-updates/s and the fraction of the roofline
// `roof` (STREAM triad / 32 B), with a check that the ring sweeps give the out-of-place values.
#pragma once

#include <mpi.h>

#include <algorithm>

namespace morphogen {

// Seconds of the slowest rank for one call of f, best of `reps` (a barrier before each).
template <class F> double slowest_best_seconds(MPI_Comm comm, F&& f, int reps) {
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    f();
    double dt = MPI_Wtime() - t0, dtmax = 0;
    MPI_Allreduce(&dt, &dtmax, 1, MPI_DOUBLE, MPI_MAX, comm);
    best = std::min(best, dtmax);
  }
  return best;
}

void bench_access_pattern(MPI_Comm comm, int rows, double roof);

// The 3-D patterns (bench_access_pattern_3d.cpp), side^3 cells over the ranks (side x side x
// side / P per rank): the 7-point in-place sweep in blocks of y rows through a ring (as the
// explicit fast path), with and without its prefetch, without the blocks, and out of place; and
// the in-place sweep reading the 9 rows of the 19/27-point stencils (3d_ring_9row_*).
void bench_access_pattern_3d(MPI_Comm comm, int side, double roof);

} // namespace morphogen
