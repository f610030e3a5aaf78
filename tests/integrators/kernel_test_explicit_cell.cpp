// The per-cell explicit update of the CUDA path (explicit_cell) against the CPU row kernel
// (explicit_row) on periodic ghosted boxes: 2-D 5pt and 9pt, 3-D 7pt, several models, 20 steps.
// Both compile here with the same flags and no FMA contraction (CMakeLists.txt), and write the
// same fused multiply-adds in the same order (the taps scaled by dt D once per row there, per
// cell here: the same products), so the results are bitwise equal after 20 steps.
#include "cuda/cpu_reference.hpp"
#include "models/all_models.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace morphogen;
using namespace morphogen::gpu;

namespace {

RowStencil rows_of(int dim, bool box) {
  RowStencil r;
  if (dim == 2 && box) { // 9pt: 0.2 edges, 0.05 corners (Garrity), scaled to sum 0
    r.nrows = 3;
    r.box = true;
    r.off[0] = {0, 0};
    r.off[1] = {-1, 0};
    r.off[2] = {1, 0};
    const double c[9] = {0.2, -1.0, 0.2, 0.05, 0.2, 0.05, 0.05, 0.2, 0.05};
    for (int q = 0; q < 9; ++q)
      r.w[q] = c[q];
    return r;
  }
  r.nrows = dim == 2 ? 3 : 5;
  const int off[5][2] = {{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  for (int q = 0; q < r.nrows; ++q) {
    r.off[q] = {off[q][0], off[q][1]};
    r.w[3 * q + 1] = q == 0 ? -2.0 * dim : 1.0;
  }
  r.w[0] = r.w[2] = 1.0;
  return r;
}

template <class M> std::vector<std::vector<double>> start(const GhostedBox& g, const double* p) {
  return perturbed_start<M>(g, p, [](int s, int i, int j, int k) {
    return 0.5 * std::sin(0.7 * i + 1.3 * j + 0.4 * k + s);
  });
}

template <class M, int NR, bool Box> void compare(int dim, int n) {
  const GhostedBox g = make_ghosted_box(n, n + 3, n + 1, dim);
  const RowStencil rows = rows_of(dim, Box);
  ASSERT_EQ(rows.nrows, NR);
  CellCoefficients<M::nspecies, M::nparams> k{};
  for (int q = 0; q < M::nparams; ++q)
    k.p[q] = M::params[q].def;
  for (int s = 0; s < M::nspecies; ++s) {
    k.D[s] = 0.1 * (s + 1);
    k.floor[s] = M::clamp_default ? 0.0 : -INFINITY;
  }
  k.dt = 0.01;
  auto row = start<M>(g, k.p), tmp = row, cell = row, ctmp = row;
  explicit_steps_host<M, NR, Box>(g, rows, k, 20, row, tmp);
  const CellStencil<NR> st = cell_stencil<NR>(rows, g);
  for (int step = 0; step < 20; ++step) {
    const double* in[M::nspecies];
    double* out[M::nspecies];
    for (int s = 0; s < M::nspecies; ++s) {
      fill_ghosts_host(g, cell[s].data());
      in[s] = cell[s].data();
      out[s] = ctmp[s].data();
    }
    for (int kk = 0; kk < g.n[2]; ++kk)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i)
          explicit_cell<M, NR, Box>(in, g.index(i, j, kk), st, k, out, g.index(i, j, kk));
    std::swap(cell, ctmp);
  }
  double diff = 0, scale = 0, change = 0;
  const auto first = start<M>(g, k.p);
  for (int s = 0; s < M::nspecies; ++s)
    for (int kk = 0; kk < g.n[2]; ++kk)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const long c = g.index(i, j, kk);
          diff = std::max(diff, std::fabs(row[s][c] - cell[s][c]));
          scale = std::max(scale, std::fabs(row[s][c]));
          change = std::max(change, std::fabs(row[s][c] - first[s][c]));
        }
  std::printf("%-16s %dD %s: max |cell - row| = %.3e (max |u| %.3e)\n", M::name, dim,
              Box ? "box" : "star", diff, scale);
  EXPECT_EQ(diff, 0.0) << M::name << " " << dim << "D";
  EXPECT_GT(change, 1e-4) << "the steps must change the state for the comparison to mean much";
}

} // namespace

TEST(ExplicitCell, MatchesRowKernel2DStar) {
  compare<models::GrayScott, 3, false>(2, 24);
  compare<models::Brusselator, 3, false>(2, 24);
  compare<models::FitzHughNagumo, 3, false>(2, 24);
}

TEST(ExplicitCell, MatchesRowKernel2DBox) {
  compare<models::GrayScott, 3, true>(2, 24);
  compare<models::Turing, 3, true>(2, 24);
}

TEST(ExplicitCell, MatchesRowKernel3D) {
  compare<models::GrayScott, 5, false>(3, 12);
  compare<models::Barkley, 5, false>(3, 12);
}

TEST(ExplicitCell, PeriodicGhostsWrap) {
  const GhostedBox g = make_ghosted_box(4, 3, 2, 3);
  std::vector<double> u(g.size(), -1.0);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i)
        u[g.index(i, j, k)] = i + 10 * j + 100 * k;
  fill_ghosts_host(g, u.data());
  EXPECT_EQ(u[g.index(-1, 0, 0)], 3.0);
  EXPECT_EQ(u[g.index(4, 2, 1)], 0 + 20 + 100);
  EXPECT_EQ(u[g.index(-1, -1, -1)], 3 + 20 + 100); // corner through all three axes
  EXPECT_EQ(u[g.index(1, 3, 0)], 1.0);
}
