// One cell of the fused explicit Euler update: the per-cell form of explicit_row
// (integrators/explicit_kernel.hpp) for the CUDA path, with the same operations in the same
// order (the same fused multiply-adds: fma here, std::fma there). For each species s, with the
// stencil in row form (grid/stencil.hpp, RowStencil):
//   out_s = max( fma(dt, R_s, u_s) + sum_r sum_c W_s[r][c] u_s(x+c-1, r),  floor_s )
// with W_s[r][c] = (dt D_s) w[r][c] (the Euler step u + dt (D lap + R), dt D folded into the
// weights).
// u[s] is species s's ghosted array and c the cell's index in it; stencil row r starts at
// c + roff[r] (roff[0] = 0) and x neighbours are at -+1. Star stencils (Box = false) use only the
// centre tap of rows r > 0. out[s][o] receives the result (o: the cell's index in the output).
#pragma once

#include "fields/clamp_kernel.hpp"
#include "models/model.hpp"

#include <math.h>

namespace morphogen {

template <int NR> struct CellStencil {
  long roff[NR];   // offset of stencil row r from the cell (row 0: 0)
  double w[NR][3]; // x-taps of row r (include 1/h^2)
};

template <int NS, int NP> struct CellCoefficients {
  double D[NS];              // diffusion coefficients
  double floor[NS];          // lower bounds (0 or -inf)
  double p[NP > 0 ? NP : 1]; // parameter scalars
  double dt;
};

template <class M, int NR, bool Box>
MG_HD inline void explicit_cell(const double* const* u, long c, const CellStencil<NR>& st,
                                const CellCoefficients<M::nspecies, M::nparams>& k,
                                double* const* out, long o) {
  constexpr int NS = M::nspecies;
  double uc[NS], r[NS];
  for (int s = 0; s < NS; ++s)
    uc[s] = u[s][c];
  M::rates(uc, k.p, r);
  for (int s = 0; s < NS; ++s) {
    const double* us = u[s] + c;
    const double f = k.dt * k.D[s];
    double v = fma(k.dt, r[s], uc[s]);
    v = fma(f * st.w[0][2], us[1], fma(f * st.w[0][1], uc[s], fma(f * st.w[0][0], us[-1], v)));
    for (int q = 1; q < NR; ++q) {
      const double* row = us + st.roff[q];
      if constexpr (Box)
        v += fma(f * st.w[q][2], row[1], fma(f * st.w[q][1], row[0], (f * st.w[q][0]) * row[-1]));
      else
        v = fma(f * st.w[q][1], row[0], v);
    }
    out[s][o] = clamp_to_floor(v, k.floor[s]);
  }
}

// Periodic ghost layer of width 1 on a ghosted box of n[0..2] owned cells per axis (n[2] = 1 and
// no z ghosts in 2-D), filled one axis at a time so corners come out right when the axes are
// done in order x, y, z. fill_periodic_ghost fills the two ghosts of the line `line` (its
// position in the ghosted face orthogonal to `axis`).
struct GhostedBox {
  int n[3];                                     // owned cells per axis
  int dim;                                      // 2 or 3
  long st[3];                                   // strides of the ghosted array per axis
  MG_HD long index(int i, int j, int k) const { // ghosted index of owned cell (i, j, k)
    return (i + 1) * st[0] + (j + 1) * st[1] + (dim == 3 ? (k + 1) * st[2] : 0);
  }
  MG_HD long size() const { return st[dim - 1] * (n[dim - 1] + 2); }
};

MG_HD inline GhostedBox make_ghosted_box(int nx, int ny, int nz, int dim) {
  GhostedBox b{{nx, ny, dim == 3 ? nz : 1}, dim, {1, nx + 2L, (nx + 2L) * (ny + 2L)}};
  return b;
}

// Ghost pair of the line through ghosted-face position (a, b) (the other two axes' ghosted
// coordinates, 0..n+1) along `axis`: u[0] = u[n], u[n+1] = u[1].
MG_HD inline void fill_periodic_ghost(const GhostedBox& g, int axis, int a, int b, double* u) {
  const int o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
  const long base = a * g.st[o1] + (g.dim == 3 || o2 != 2 ? b * g.st[o2] : 0);
  const long s = g.st[axis];
  const int n = g.n[axis];
  u[base] = u[base + n * s];
  u[base + (n + 1) * s] = u[base + s];
}

} // namespace morphogen
