// Units of `morphogen screen`: the set sampling (grid order, rank-free random values, LHS
// strata: every stratum of every axis exactly once) and the closed-form 2x2 Turing analysis
// against the general analysis (eigenvalues and a k scan) on random systems.
#include "analysis/linear_stability.hpp"
#include "analysis/turing_2x2.hpp"
#include "core/hash_rng.hpp"
#include "sweep/screen_sampling.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace morphogen;
using morphogen::sweep::Sampling;
using morphogen::sweep::ScreenSampler;

TEST(ScreenSampling, GridFirstAxisFastestWithExactEnds) {
  ScreenSampler s;
  s.names = {"alpha", "beta"};
  s.lo = {1, 10}, s.hi = {2, 20}, s.points = {3, 5};
  ASSERT_EQ(s.total(), 15);
  double v[2];
  s.values(0, v);
  EXPECT_EQ(v[0], 1);
  EXPECT_EQ(v[1], 10);
  s.values(1, v);
  EXPECT_EQ(v[0], 1.5);
  s.values(14, v);
  EXPECT_EQ(v[0], 2);
  EXPECT_EQ(v[1], 20);
  s.values(3 * 2 + 2, v);
  EXPECT_EQ(v[0], 2);
  EXPECT_EQ(v[1], 15);
}

TEST(ScreenSampling, PermutationIsABijection) {
  for (long long n : {1LL, 2LL, 3LL, 17LL, 1000LL, 4097LL}) {
    std::vector<char> hit(static_cast<size_t>(n), 0);
    for (long long i = 0; i < n; ++i) {
      const long long p = sweep::permute(i, n, 5, 11);
      ASSERT_GE(p, 0);
      ASSERT_LT(p, n);
      hit[static_cast<size_t>(p)]++;
    }
    EXPECT_EQ(std::count(hit.begin(), hit.end(), 1), n) << n;
  }
}

TEST(ScreenSampling, LatinHypercubeFillsEveryStratumOnce) {
  ScreenSampler s;
  s.sampling = Sampling::Lhs;
  s.names = {"a", "b", "c"};
  s.lo = {0, -1, 5}, s.hi = {1, 1, 6}, s.count = 999, s.seed = 3;
  std::vector<std::vector<int>> hits(3, std::vector<int>(999, 0));
  double v[3];
  for (long long i = 0; i < 999; ++i) {
    s.values(i, v);
    for (int j = 0; j < 3; ++j) {
      const double f = (v[j] - s.lo[j]) / (s.hi[j] - s.lo[j]) * 999;
      ASSERT_GE(f, 0);
      ++hits[j][std::min(998, static_cast<int>(f))];
    }
  }
  for (int j = 0; j < 3; ++j)
    EXPECT_EQ(std::count(hits[j].begin(), hits[j].end(), 1), 999) << j;
  // the axes are not permuted alike
  int same = 0;
  for (long long i = 0; i < 999; ++i)
    same += sweep::permute(i, 999, 3, 1) == sweep::permute(i, 999, 3, 2);
  EXPECT_LT(same, 20);
}

TEST(ScreenSampling, RandomValuesAreAPureFunctionOfSeedAndIndex) {
  ScreenSampler s;
  s.sampling = Sampling::Random;
  s.names = {"a", "b"};
  s.lo = {0, 0}, s.hi = {2, 4}, s.count = 100, s.seed = 9;
  double v[2], w[2];
  s.values(42, v);
  s.values(42, w);
  EXPECT_EQ(v[0], w[0]);
  EXPECT_EQ(v[1], w[1]);
  EXPECT_NE(v[0] / 2, v[1] / 4); // independent streams per axis
  s.seed = 10;
  s.values(42, w);
  EXPECT_NE(v[0], w[0]);
}

TEST(Turing2x2, AgreesWithTheGeneralAnalysisOnRandomSystems) {
  int turing = 0;
  for (std::uint64_t t = 0; t < 4000; ++t) {
    double J[4], D[2];
    for (int i = 0; i < 4; ++i)
      J[i] = 4 * rng::uniform(1, 1, 6 * t + i) - 2;
    D[0] = std::exp(4 * rng::uniform(1, 2, 6 * t + 4) - 2);
    D[1] = std::exp(4 * rng::uniform(1, 2, 6 * t + 5) - 2);
    if (t % 2) { // activator-inhibitor with a fast inhibitor: Turing-prone
      J[0] = std::abs(J[0]), J[3] = -std::abs(J[3]) - 1;
      D[1] = D[0] * std::exp(6 * rng::uniform(1, 3, t));
    }
    const auto fast = analysis::turing_2x2(J, D);
    ASSERT_TRUE(fast.handled);
    analysis::StabilityOptions opt;
    opt.samples = 4096;
    const auto gen = analysis::analyse_jacobian(2, J, D, opt);
    ASSERT_EQ(fast.stable_homogeneous, gen.stable_homogeneous) << t;
    if (std::abs(gen.growth_fastest) < 1e-6) continue; // at a threshold: either verdict
    ASSERT_EQ(fast.turing_unstable, gen.turing_unstable) << t;
    if (!fast.turing_unstable) continue;
    ++turing;
    EXPECT_NEAR(fast.growth_fastest, gen.growth_fastest, 1e-9 * (1 + gen.growth_fastest)) << t;
    EXPECT_NEAR(std::sqrt(fast.q_fastest), gen.k_fastest, 1e-5 * gen.k_fastest) << t;
    EXPECT_GE(fast.growth_fastest, analysis::growth_2x2(J, D, fast.q_fastest * 1.001));
    EXPECT_GE(fast.growth_fastest, analysis::growth_2x2(J, D, fast.q_fastest * 0.999));
  }
  EXPECT_GT(turing, 50);
}

TEST(Turing2x2, EqualOrZeroDiffusion) {
  const double J[4] = {1, -1, 3, -2}; // stable (trace -1, det 1), activator-inhibitor
  const double same[2] = {1, 1}, zero[2] = {0, 1};
  const auto r = analysis::turing_2x2(J, same);
  EXPECT_TRUE(r.handled && r.stable_homogeneous && !r.turing_unstable);
  EXPECT_FALSE(analysis::turing_2x2(J, zero).handled);
  const double far[2] = {0.01, 1};
  EXPECT_TRUE(analysis::turing_2x2(J, far).turing_unstable);
}
