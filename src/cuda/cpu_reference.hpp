// The CPU reference of the GPU check: explicit Euler steps of a compiled model on a periodic
// ghosted box, through the production row kernel (integrators/explicit_kernel.hpp) and the same
// ghost fill as the device path (integrators/explicit_cell_kernel.hpp).
#pragma once

#include "grid/stencil.hpp"
#include "integrators/explicit_cell_kernel.hpp"
#include "integrators/explicit_kernel.hpp"

#include <array>
#include <vector>

namespace morphogen::gpu {

// The stencil rows of `rows` as offsets in the ghosted box g.
template <int NR> CellStencil<NR> cell_stencil(const RowStencil& rows, const GhostedBox& g) {
  CellStencil<NR> st{};
  for (int r = 0; r < NR; ++r) {
    st.roff[r] = rows.off[r][0] * g.st[1] + rows.off[r][1] * (g.dim == 3 ? g.st[2] : 0);
    for (int c = 0; c < 3; ++c)
      st.w[r][c] = rows.w[3 * r + c];
  }
  return st;
}

// Ghosted arrays of model M's homogeneous steady state (the species' initial values where it has
// none) plus 0.05 wiggle(s, i, j, k) on each owned cell, wiggle in [-0.5, 0.5].
template <class M, class Wiggle>
std::vector<std::vector<double>> perturbed_start(const GhostedBox& g, const double* p,
                                                 Wiggle wiggle) {
  double u0[M::nspecies];
  if (!M::steady_state(p, u0))
    for (int s = 0; s < M::nspecies; ++s)
      u0[s] = M::species[s].init;
  std::vector<std::vector<double>> u(M::nspecies, std::vector<double>(g.size(), 0.0));
  for (int s = 0; s < M::nspecies; ++s)
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i)
          u[s][g.index(i, j, k)] = u0[s] + 0.05 * wiggle(s, i, j, k);
  return u;
}

// Periodic ghosts of one species' ghosted array on the host (x, then y, then z).
inline void fill_ghosts_host(const GhostedBox& g, double* u) {
  for (int axis = 0; axis < g.dim; ++axis) {
    const int o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
    const int na = g.n[o1] + 2, nb = g.dim == 3 ? g.n[o2] + 2 : 1;
    for (int b = 0; b < nb; ++b)
      for (int a = 0; a < na; ++a)
        fill_periodic_ghost(g, axis, a, b, u);
  }
}

// `steps` explicit steps of model M on the ghosted arrays u (per species; ghosts are filled
// here), using tmp as the second buffer; the result ends in u.
template <class M, int NR, bool Box>
void explicit_steps_host(const GhostedBox& g, const RowStencil& rows,
                         const CellCoefficients<M::nspecies, M::nparams>& k, int steps,
                         std::vector<std::vector<double>>& u,
                         std::vector<std::vector<double>>& tmp) {
  constexpr int NS = M::nspecies;
  const CellStencil<NR> st = cell_stencil<NR>(rows, g);
  for (int n = 0; n < steps; ++n) {
    for (int s = 0; s < NS; ++s)
      fill_ghosts_host(g, u[s].data());
    for (int kk = 0; kk < g.n[2]; ++kk)
      for (int j = 0; j < g.n[1]; ++j) {
        const long c = g.index(0, j, kk);
        const double* src[NS * NR];
        double* dst[NS];
        for (int s = 0; s < NS; ++s) {
          for (int r = 0; r < NR; ++r)
            src[s * NR + r] = u[s].data() + c + st.roff[r];
          dst[s] = tmp[s].data() + c;
        }
        ExplicitRow a;
        a.n = g.n[0];
        a.src = src;
        a.w = rows.w.data();
        a.D = k.D;
        a.floor = k.floor;
        a.pconst = k.p;
        a.dt = k.dt;
        a.dst = dst;
        explicit_row<M, NR, Box, kScalarParams>(a);
      }
    std::swap(u, tmp);
  }
}

} // namespace morphogen::gpu
