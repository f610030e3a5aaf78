// The setup and output section of morphogen-bench (issue 13 parts 3 and 4): on Turing Fig. 1 at
// 4096^2 (the default deck's parameters), the cost of filling parameter fields (ns per cell per
// field: a perturbed constant "12 +- 0.1% gauss" and a muParser expression of x and y; target
// <= 50), the PNG quick-looks of both species (seconds; target <= 1 s), and the process's peak
// resident memory per cell after setup, two steps and the images (getrusage; target <= 64 B,
// run first so nothing else in the bench has grown the peak). Writes into a temporary directory
// that it removes.
#pragma once

#include "core/options.hpp"

#include <mpi.h>

namespace morphogen {

void bench_output(MPI_Comm comm, Options& opt, int n);

} // namespace morphogen
