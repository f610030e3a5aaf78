// The machine a morphogen-bench run measured, read on rank 0 from Linux's /proc/cpuinfo and
// /sys/devices/system/cpu/cpu0/cache (fields it cannot read stay empty or 0), and how much of
// the last-level cache a grid's state would fill: the bench's "out of cache" grids (2048^2,
// 4096^2, 256^3: 64-256 MiB of state) fit in the L3 of some servers (hundreds of MiB), where a
// step is partly served from the cache and its fraction of the DRAM roofline says so.
//
// Printed line (rank 0):
//   machine cpu="<model name>" logical_cpus=N l1d_KiB=A l2_KiB=B l3_MiB=C avx512=yes|no
//           nodes=M ranks_per_node=R
#pragma once

#include <mpi.h>

#include <string>

namespace morphogen {

struct MachineInfo {
  std::string cpu;                                  // /proc/cpuinfo "model name" (empty: unknown)
  int logical_cpus = 0;                             // online logical CPUs of this node
  double l1d_bytes = 0, l2_bytes = 0, l3_bytes = 0; // per instance, as the kernel lists them
  bool avx512 = false;                              // the "avx512f" flag
  int nodes = 1, ranks_per_node = 1;                // of the communicator (shared-memory groups)
};

// Collective on comm: rank 0 reads the files; the node count is the number of shared-memory
// groups (MPI_Comm_split_type) and ranks_per_node rank 0's group size.
MachineInfo read_machine_info(MPI_Comm comm);

// Collective: reads the machine and prints its line on rank 0.
MachineInfo print_machine(MPI_Comm comm);

// " state_MiB_per_node=S in_l3=yes|no" for the bench's 2-species grids of `cells` cells in double
// (16 bytes per cell), spread evenly over m.nodes nodes; in_l3=unknown where the L3 size is
// unknown.
std::string l3_note(double cells, const MachineInfo& m);

} // namespace morphogen
