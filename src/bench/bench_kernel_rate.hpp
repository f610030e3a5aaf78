// The explicit row kernel alone (issue 13 part 2, the arithmetic ceiling): the fused Gray-Scott
// row kernel of a stencil (2-D 5pt, 9pt; 3-D 7pt, 19pt, 27pt, the box stencils in their
// weight-class form as the explicit integrator runs them; h = 1) swept over rows of `n` cells
// that stay in the per-core caches, on every rank at once, in each compile (256-bit, 512-bit).
//   ns per cell = best over reps of (slowest rank's seconds) / (calls * n)
//   ceiling     = ranks / (least ns per cell)   [cell-updates per second]
// Fused passes redo the same arithmetic per step, so the ceiling bounds them; a single step out
// of cache whose arithmetic and memory traffic do not overlap takes the sum of both times,
//   serial bound = 1 / (1 / ceiling + 1 / roofline).
#pragma once

#include <mpi.h>

#include <string>

namespace morphogen {

struct RowKernelRate {
  double ns_per_cell[2] = {0, 0}; // [wide]: 256-bit, 512-bit compile
  double ceiling = 0;             // cell-updates per second on all ranks, faster compile
};

RowKernelRate time_row_kernel(MPI_Comm comm, const std::string& stencil, int dim, int n);

// A fused pass's wavefront (integrators/fused_sweep.hpp) of `levels` levels over rows of n cells
// of a 2-D stencil, every row in its ring (no memory traffic: the first level's reads and the
// last level's writes of the state left out): ns per cell-update, faster compile, slowest rank.
double time_fused_ring(MPI_Comm comm, const std::string& stencil, int n, int levels);
// Prints it as explicit_fused_ring with its rate on all ranks and fraction of `roof`.
void print_fused_ring_bound(MPI_Comm comm, const std::string& stencil, double roof, int n,
                            int levels);

// Prints the kernel's rates on rows of n cells, the ceiling and the serial bound against `roof`
// (cell-updates/s).
void print_row_kernel_bounds(MPI_Comm comm, const std::string& stencil, int dim, double roof,
                             int n);

} // namespace morphogen
