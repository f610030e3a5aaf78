// The access-pattern section of morphogen-bench (-bench_access_rows, issue 13 part 2): the memory
// side of an explicit 2-D step without its arithmetic. Two species of R rows x 4096 cells per
// rank (ghosted rows of 4098, as the grid's), each pattern swept once per repetition with the
// cheapest arithmetic that keeps its loads and stores (u <- u + 0.1 (sum of taps - n u)):
//   in_place_pointwise   u(i) from u(i) only, written back in place (one read, one write stream)
//   in_place_save_old    the same, also storing the old row into a two-row buffer
//   ring_pointwise       the same through a row ring: new row into the ring, copied back
//   ring_xtaps           taps i - 1, i, i + 1 of the row, through the ring
//   ring_5pt             5-point taps (rows j - 1, j, j + 1), the ring one row behind (the in-place
//                        sweep of the explicit fast path)
//   ring_5pt_prefetch    the same with the fast path's prefetch (the row two past the leading
//                        row, before each row)
//   out_of_place_5pt     5-point taps into a second state set
// printed as ns per cell and rank, aggregate cell-updates/s and the fraction of the roofline
// `roof` (STREAM triad / 32 B), with a check that the ring sweeps give the out-of-place values.
#pragma once

#include <mpi.h>

namespace morphogen {

void bench_access_pattern(MPI_Comm comm, int rows, double roof);

} // namespace morphogen
