// Unit tests of app/reaction_stiffness: the forward-Euler bound of the reaction's Jacobian,
// dt < -2 Re(lambda) / |lambda|^2 over the eigenvalues with Re(lambda) < 0, for any number of
// species (serial: the pure functions euler_bound and min_euler_bound, no MPI or PETSc calls).
//   * 2 x 2, closed form: a complex pair tr/2 +- i sqrt(det - tr^2/4) gives -tr/det; real
//     eigenvalues l < 0 give -2/l. The general path (dgeev) must agree with it.
//   * 3 x 3, by hand: P diag-block([[-1, 3], [-3, -1]], -1) P^-1 with P = [[1,1,0],[0,1,1],
//     [0,0,1]] is [[-4, 6, -6], [-3, 2, -3], [0, 0, -1]]: eigenvalues -1 +- 3i (bound
//     2 / 10 = 0.2) and -1 (bound 2); the pair sets it. Upper triangular [[-5, 1, 2],
//     [0, -0.5, 7], [0, 0, 3]]: -5 (0.4), -0.5 (4), 3 (no bound): 0.4.
//   * 4 x 4 block upper triangular: the eigenvalues are the diagonal blocks'.
//   * The cell scan: one Jacobian per distinct key, the cell that sets the bound, the sample of
//     every s-th cell beyond max_eigen distinct keys (n > 2), every cell for n = 2; and its
//     cost at 1024^2 cells (printed).
#include "app/reaction_stiffness.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace morphogen {
namespace {

TEST(ReactionStiffness, TwoByTwoClosedFormByHand) {
  const double complex_pair[4] = {-1, 2, -3, -2}; // tr -3, det 8: -1.5 +- i sqrt(5.75)
  EigenBound b = euler_bound(2, complex_pair);
  EXPECT_DOUBLE_EQ(b.dt, 3.0 / 8.0);
  EXPECT_DOUBLE_EQ(b.lambda_re, -1.5);
  EXPECT_NEAR(b.lambda_im, std::sqrt(5.75), 1e-14);
  const double real_pair[4] = {-4, 0, 0, -1}; // -4 (0.5), -1 (2)
  b = euler_bound(2, real_pair);
  EXPECT_DOUBLE_EQ(b.dt, 0.5);
  EXPECT_DOUBLE_EQ(b.lambda_re, -4);
  EXPECT_EQ(b.lambda_im, 0);
  const double growing[4] = {1, 0, 0, 2}; // no decaying mode
  EXPECT_TRUE(std::isinf(euler_bound(2, growing).dt));
  EXPECT_TRUE(std::isinf(euler_bound(2, growing, true).dt));
  // Turk's kinetics at the Fig. 1 state: J = s[[3, 4], [-4, -4]], s = 1/128: tr -s, det 4 s^2,
  // a complex pair, bound -tr/det = 1/(4 s) = 32.
  const double s = 1.0 / 128, turing[4] = {3 * s, 4 * s, -4 * s, -4 * s};
  EXPECT_NEAR(euler_bound(2, turing).dt, 32, 1e-12);
  EXPECT_NEAR(euler_bound(2, turing, true).dt, 32, 1e-10);
}

TEST(ReactionStiffness, GeneralPathMatchesTwoByTwoClosedForm) {
  std::mt19937 gen(7);
  std::normal_distribution<double> nd;
  int finite = 0;
  for (int t = 0; t < 20000; ++t) {
    double J[4];
    for (double& x : J)
      x = nd(gen) * std::pow(10.0, (t % 7) - 3); // scales 1e-3 .. 1e3
    const EigenBound closed = euler_bound(2, J), general = euler_bound(2, J, true);
    ASSERT_EQ(std::isinf(closed.dt), std::isinf(general.dt)) << t;
    if (std::isinf(closed.dt)) continue;
    ++finite;
    ASSERT_NEAR(general.dt, closed.dt, 1e-9 * closed.dt) << t;
    ASSERT_NEAR(general.lambda_re, closed.lambda_re, 1e-9 * std::abs(closed.lambda_re)) << t;
    ASSERT_NEAR(general.lambda_im, closed.lambda_im,
                1e-9 * std::hypot(closed.lambda_re, closed.lambda_im))
        << t;
  }
  EXPECT_GT(finite, 10000); // most random 2x2 matrices have a decaying eigenvalue
}

TEST(ReactionStiffness, ThreeByThreeByHand) {
  const double rotated[9] = {-4, 6, -6, -3, 2, -3, 0, 0, -1}; // -1 +- 3i, -1
  EigenBound b = euler_bound(3, rotated);
  EXPECT_NEAR(b.dt, 0.2, 1e-12);
  EXPECT_NEAR(b.lambda_re, -1, 1e-12);
  EXPECT_NEAR(b.lambda_im, 3, 1e-12);
  const double triangular[9] = {-5, 1, 2, 0, -0.5, 7, 0, 0, 3}; // -5, -0.5, 3
  b = euler_bound(3, triangular);
  EXPECT_NEAR(b.dt, 0.4, 1e-12);
  EXPECT_NEAR(b.lambda_re, -5, 1e-12);
  EXPECT_EQ(b.lambda_im, 0);
  const double one[1] = {-8};
  EXPECT_DOUBLE_EQ(euler_bound(1, one).dt, 0.25);
  const double nan3[9] = {NAN, 0, 0, 0, -1, 0, 0, 0, -1};
  EXPECT_TRUE(std::isinf(euler_bound(3, nan3).dt));
}

// Two uncoupled copies of Turk's 2x2 block (layers without mixing) plus a coupling above the
// diagonal: block upper triangular, so the eigenvalues are the blocks'.
TEST(ReactionStiffness, FourSpeciesBlockTriangular) {
  const double s1 = 1.0 / 128, s2 = 1.0 / 16;              // bounds 1/(4 s): 32 and 4
  const double J[16] = {3 * s1,  4 * s1,  0.3,     -0.2,   //
                        -4 * s1, -4 * s1, 0.1,     0.5,    //
                        0,       0,       3 * s2,  4 * s2, //
                        0,       0,       -4 * s2, -4 * s2};
  const EigenBound b = euler_bound(4, J);
  EXPECT_NEAR(b.dt, 4, 1e-10);
  EXPECT_NEAR(b.lambda_re, -0.5 * s2, 1e-12);
  EXPECT_NEAR(b.lambda_im, std::sqrt(4 * s2 * s2 - 0.25 * s2 * s2), 1e-12);
}

// The cell scan: deduplication, the cell that sets the bound, and the sample beyond max_eigen.
TEST(ReactionStiffness, CellScanDeduplicatesAndSamples) {
  const double rotated[9] = {-4, 6, -6, -3, 2, -3, 0, 0, -1}; // bound 0.2
  const long long cells = 1000;
  // Uniform but for cell 617, whose Jacobian is twice as stiff (bound 0.1).
  auto jac = [&](long long c, double* J) {
    for (int t = 0; t < 9; ++t)
      J[t] = (c == 617 ? 2 : 1) * rotated[t];
  };
  CellsBound r = min_euler_bound(3, cells, 9, jac, jac);
  EXPECT_EQ(r.distinct, 2);
  EXPECT_EQ(r.evaluated, 2);
  EXPECT_EQ(r.stride, 1);
  EXPECT_EQ(r.cell, 617);
  EXPECT_NEAR(r.bound.dt, 0.1, 1e-12);
  // Every cell distinct (a perturbed parameter) beyond max_eigen = 100: every 10th cell.
  auto noisy = [&](long long c, double* J) {
    for (int t = 0; t < 9; ++t)
      J[t] = (1 + 1e-6 * static_cast<double>(c)) * rotated[t];
  };
  r = min_euler_bound(3, cells, 9, noisy, noisy, 100);
  EXPECT_EQ(r.stride, 10);
  EXPECT_EQ(r.evaluated, 100);
  EXPECT_EQ(r.cell, 990); // the stiffest sampled cell
  EXPECT_NEAR(r.bound.dt, 0.2 / (1 + 990e-6), 1e-12);
  // n = 2 scans every cell with the closed form, whatever max_eigen.
  auto two = [&](long long c, double* J) {
    J[0] = -1, J[1] = 2, J[2] = -3, J[3] = (c == 3 ? -20 : -2);
  };
  r = min_euler_bound(2, cells, 4, two, two, 1);
  // Elsewhere 0.375 (tr -3, det 8); cell 3: tr -21, det 26, real -10.5 +- sqrt(84.25).
  EXPECT_EQ(r.cell, 3);
  EXPECT_NEAR(r.bound.dt, 2 / (10.5 + std::sqrt(84.25)), 1e-14);
  EXPECT_EQ(r.stride, 1);
  EXPECT_EQ(r.evaluated, cells); // 2 distinct > max_eigen 1: every cell, closed form
}

// The cost at 1024^2 cells on one rank, with 3 species: a uniform state (one dgeev) and a state
// where every cell differs (the sample). Prints the times; the limit is generous (load).
TEST(ReactionStiffness, CostAt1024Squared) {
  const long long cells = 1024LL * 1024;
  const double rotated[9] = {-4, 6, -6, -3, 2, -3, 0, 0, -1};
  for (int noisy = 0; noisy < 2; ++noisy) {
    auto jac = [&](long long c, double* J) {
      const double f = noisy ? 1 + 1e-9 * static_cast<double>(c) : 1;
      for (int t = 0; t < 9; ++t)
        J[t] = f * rotated[t];
    };
    const auto t0 = std::chrono::steady_clock::now();
    const CellsBound r = min_euler_bound(3, cells, 9, jac, jac);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("1024^2 cells, 3 species, %s: %.3f s (%lld distinct, %lld dgeev, stride %lld)\n",
                noisy ? "every cell distinct" : "uniform", sec, r.distinct, r.evaluated, r.stride);
    EXPECT_LT(sec, 3.0);
    EXPECT_NEAR(r.bound.dt, 0.2, 1e-3);
    if (noisy) {
      EXPECT_GT(r.stride, 1);
    }
  }
}

} // namespace
} // namespace morphogen
