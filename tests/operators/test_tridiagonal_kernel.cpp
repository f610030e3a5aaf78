// The slow-axis tridiagonal row kernels (operators/tridiagonal_kernel.hpp), serial:
//  (a) the Crank-Nicolson product plane by plane with a x_{j-1} carried
//      (tri_times_row, then tri_multiply_row_carry in place) gives bitwise the values of the
//      product s0 x_j + s1 ((a x_{j-1} + b_j x_j) + g x_{j+1}) of the raw rows (evaluated here
//      on copies of them, as TridiagonalSolver did before), for random rows, per-lane
//      coefficients, distinct first/interior/last diagonals and scales;
//  (b) Thomas elimination by rows (tri_forward_row, then tri_backward_row with gp = g inv)
//      solves a diagonally dominant system per lane to 1e-13 relative (residual of the
//      original equations).
#include "operators/tridiagonal_kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

using namespace morphogen;

namespace {

using Rows = std::vector<std::vector<double>>;

Rows random_rows(int m, int n, std::mt19937& gen, double lo, double hi) {
  std::uniform_real_distribution<double> d(lo, hi);
  Rows r(static_cast<size_t>(m), std::vector<double>(static_cast<size_t>(n)));
  for (auto& row : r)
    for (double& x : row)
      x = d(gen);
  return r;
}

bool same_bits(double x, double y) {
  return std::memcmp(&x, &y, sizeof x) == 0;
}

} // namespace

TEST(TridiagonalKernel, CarriedProductIsBitwiseTheCopiedOne) {
  const int n = 37, m = 9;
  std::mt19937 gen(20261207);
  const Rows raw = random_rows(m, n, gen, -2.0, 2.0);
  const Rows coef = random_rows(5, n, gen, -1.0, 1.0);  // a, g, b_first, b_interior, b_last
  const Rows edges = random_rows(2, n, gen, -2.0, 2.0); // the rows below and above the block
  const double s0 = 0.37, s1 = -1.3;
  auto diag = [&](int j) { return (j == 0 ? coef[2] : j == m - 1 ? coef[4] : coef[3]).data(); };
  const std::vector<double>&a = coef[0], &g = coef[1], &lo = edges[0], &hi = edges[1];

  Rows ref = raw; // as before: each raw row copied aside, then overwritten by its product
  std::vector<double> prev(lo), cur(static_cast<size_t>(n));
  for (int j = 0; j < m; ++j) {
    cur = ref[static_cast<size_t>(j)];
    const double* next = j + 1 < m ? raw[static_cast<size_t>(j + 1)].data() : hi.data();
    const double* b = diag(j);
    for (int l = 0; l < n; ++l) {
      const size_t L = static_cast<size_t>(l);
      ref[static_cast<size_t>(j)][L] =
          s0 * cur[L] + s1 * ((a[L] * prev[L] + b[L] * cur[L]) + g[L] * next[L]);
    }
    prev = cur;
  }

  Rows got = raw; // carried: a x_{j-1} from the row before, in place
  std::vector<double> pa(static_cast<size_t>(n));
  tri_times_row(n, a.data(), lo.data(), pa.data());
  for (int j = 0; j < m; ++j)
    tri_multiply_row_carry(n, s0, s1, a.data(), diag(j), g.data(), pa.data(),
                           j + 1 < m ? got[static_cast<size_t>(j + 1)].data() : hi.data(),
                           got[static_cast<size_t>(j)].data());

  int differ = 0;
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < n; ++l)
      differ += !same_bits(got[static_cast<size_t>(j)][static_cast<size_t>(l)],
                           ref[static_cast<size_t>(j)][static_cast<size_t>(l)]);
  EXPECT_EQ(differ, 0) << "entries whose bits differ, of " << m * n;
  // Not vacuous: the product changed the rows.
  EXPECT_NE(got[4][7], raw[4][7]);
}

TEST(TridiagonalKernel, ThomasRowsSolveTheSystem) {
  const int n = 29, m = 12;
  std::mt19937 gen(7);
  const Rows coef = random_rows(2, n, gen, -1.0, 1.0); // a, g per lane
  const Rows b = random_rows(m, n, gen, 2.5, 4.0);     // diagonal per row and lane: dominant
  const Rows f = random_rows(m, n, gen, -1.0, 1.0);
  const std::vector<double>&a = coef[0], &g = coef[1];
  // Factors: inv_j = 1 / (b_j - a gp_{j-1}), gp_j = g inv_j.
  Rows inv(static_cast<size_t>(m), std::vector<double>(static_cast<size_t>(n)));
  Rows gp = inv;
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < n; ++l) {
      const double d = b[static_cast<size_t>(j)][static_cast<size_t>(l)] -
                       (j > 0 ? a[static_cast<size_t>(l)] *
                                    gp[static_cast<size_t>(j - 1)][static_cast<size_t>(l)]
                              : 0.0);
      inv[static_cast<size_t>(j)][static_cast<size_t>(l)] = 1.0 / d;
      gp[static_cast<size_t>(j)][static_cast<size_t>(l)] = g[static_cast<size_t>(l)] / d;
    }
  Rows x = f;
  for (int j = 0; j < m; ++j)
    tri_forward_row(n, a.data(), inv[static_cast<size_t>(j)].data(),
                    j > 0 ? x[static_cast<size_t>(j - 1)].data() : nullptr,
                    x[static_cast<size_t>(j)].data());
  for (int j = m - 2; j >= 0; --j)
    tri_backward_row(n, gp[static_cast<size_t>(j)].data(), x[static_cast<size_t>(j + 1)].data(),
                     x[static_cast<size_t>(j)].data(), x[static_cast<size_t>(j)].data());
  double worst = 0.0;
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < n; ++l) {
      const size_t J = static_cast<size_t>(j), L = static_cast<size_t>(l);
      double r = b[J][L] * x[J][L] - f[J][L];
      if (j > 0) r += a[L] * x[J - 1][L];
      if (j + 1 < m) r += g[L] * x[J + 1][L];
      worst = std::max(worst, std::fabs(r));
    }
  EXPECT_LT(worst, 1e-13);
}
