// The temporal-blocking section of morphogen-bench (-bench_fuse_steps, issue 13 part 2): explicit
// Gray-Scott cell-updates per second at the grid sides -bench_fuse_n (2-D, periodic, the
// -bench_fuse_stencil stencil) with k = 1 and each fused depth k of -bench_fuse_steps, the ratio
// to k = 1 and to the single-step bandwidth roofline `roof` (target >= 1.5 at 4096^2), after the
// row kernel's own rate and the bounds it sets, and (k > 1) the rate of a fused pass's levels
// with every row in the ring (bench/bench_kernel_rate.hpp). One
// Simulation per grid, built with the largest k (a pass of n <= k steps is exact for any n).
#pragma once

#include "bench/bench_machine.hpp"
#include "core/options.hpp"

#include <string>
#include <vector>

namespace morphogen {

// The section's options, read (and checked) before any timing starts.
struct FusedSettings {
  std::vector<PetscInt> depth; // -bench_fuse_steps (empty: skip the section)
  std::vector<std::string> ns; // -bench_fuse_n
  std::string stencil;         // -bench_fuse_stencil
  PetscInt steps = 48;         // -bench_fuse_steps_timed
};
FusedSettings read_fused_settings(Options& opt);

// The k = 1 lines end with the grid's state per node against the machine's L3 (l3_note).
void bench_fused(MPI_Comm comm, Options& opt, const FusedSettings& fs, double roof,
                 const MachineInfo& machine);

} // namespace morphogen
