// Scaling section of morphogen-bench (issue 13 part 4).
//
// Strong scaling on this node: the explicit Gray-Scott step at 1024^2 (2-D) and 128^3 (3-D) on
// rank 0 alone (the other ranks idle) against all ranks, and the same for a STREAM triad;
// target: speedup >= 0.9 min(P, bandwidth ratio), the bandwidth ratio being what the memory
// system allows a bandwidth-bound kernel.
//
// Weak-scaling model for cluster runs: every rank owns a B = 1024^2 (2-D) or 128^3 (3-D) block;
// the per-step time on P ranks is modelled as
//   t(P) = t_node + m(P) alpha + b(P) / beta
// with t_node the step time measured here with that block per rank (all ranks of this node
// busy, so bandwidth is shared as on a full cluster node), m the halo messages and b the halo
// bytes an interior rank sends per step (from the decomposition PETSc picks for P ranks and the
// grid's stencil: faces, plus edges and corners for box stencils; one message per neighbour
// per species), alpha and beta the network latency and per-rank bandwidth (options; defaults
// for an HDR InfiniBand cluster with 64 ranks per node sharing one 200 Gb/s link). No overlap
// of communication with computation is assumed (the explicit step exchanges, then computes).
// The table is a model, not a measurement, and is printed as such.
#pragma once

#include "core/options.hpp"

#include <functional>
#include <string>

namespace morphogen {

// One timed explicit run: aggregate cell-updates/s and what the halo exchange moves.
struct ProbeRun {
  double cell_updates_per_s = 0;
  int stencil_width = 1;
  bool box_stencil = true;
  int species = 2;
};

struct ScalingProbes {
  // Aggregate STREAM triad bytes/s on `comm`.
  std::function<double(MPI_Comm)> stream;
  // Explicit Gray-Scott on `comm` for grid "nx,ny[,nz]" (options read through `opt`).
  std::function<ProbeRun(MPI_Comm, Options&, const std::string&)> explicit_run;
};

// The weak-scaling model's network (-bench_net_latency_us, -bench_net_GBps), read before any
// timing starts: seconds per message and bytes per second per rank.
struct ScalingNetwork {
  double alpha = 2e-6, beta = 25e9 / 64;
};
ScalingNetwork read_scaling_network(Options& opt);

// Prints the strong-scaling lines and the weak-scaling model. Collective on comm.
void bench_scaling(MPI_Comm comm, Options& opt, const ScalingProbes& probe,
                   const ScalingNetwork& net);

} // namespace morphogen
