// CUDA kernels of the explicit Euler step on a periodic ghosted box: one thread per owned cell
// running explicit_cell (integrators/explicit_cell_kernel.hpp, the same source as the CPU row
// kernel's arithmetic), and the ghost fill one axis at a time (x, y, z, so corners are right).
// Device arrays: one ghosted array per species (GhostedBox layout).
#pragma once

#include "integrators/explicit_cell_kernel.hpp"

#include <cuda_runtime.h>

namespace morphogen::gpu {

template <int NS> struct DeviceFields { double* u[NS]; };

template <class M, int NR, bool Box>
__global__ void explicit_step_kernel(DeviceFields<M::nspecies> in, DeviceFields<M::nspecies> out,
                                     GhostedBox g, CellStencil<NR> st,
                                     CellCoefficients<M::nspecies, M::nparams> k) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  const int j = blockIdx.y * blockDim.y + threadIdx.y;
  const int kk = blockIdx.z;
  if (i >= g.n[0] || j >= g.n[1]) return;
  const long c = g.index(i, j, kk);
  explicit_cell<M, NR, Box>(in.u, c, st, k, out.u, c);
}

template <int NS> __global__ void ghost_fill_kernel(DeviceFields<NS> f, GhostedBox g, int axis) {
  const int a = blockIdx.x * blockDim.x + threadIdx.x;
  const int b = blockIdx.y;
  const int o1 = axis == 0 ? 1 : 0;
  if (a >= g.n[o1] + 2) return;
  for (int s = 0; s < NS; ++s)
    fill_periodic_ghost(g, axis, a, b, f.u[s]);
}

// One step: ghosts of `in`, then the update into `out`.
template <class M, int NR, bool Box>
void explicit_step_device(const DeviceFields<M::nspecies>& in, const DeviceFields<M::nspecies>& out,
                          const GhostedBox& g, const CellStencil<NR>& st,
                          const CellCoefficients<M::nspecies, M::nparams>& k) {
  for (int axis = 0; axis < g.dim; ++axis) {
    const int o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
    const dim3 grid((g.n[o1] + 2 + 127) / 128, g.dim == 3 ? g.n[o2] + 2 : 1);
    ghost_fill_kernel<M::nspecies><<<grid, 128>>>(in, g, axis);
  }
  const dim3 block(128, 2);
  const dim3 grid((g.n[0] + block.x - 1) / block.x, (g.n[1] + block.y - 1) / block.y, g.n[2]);
  explicit_step_kernel<M, NR, Box><<<grid, block>>>(in, out, g, st, k);
}

} // namespace morphogen::gpu
