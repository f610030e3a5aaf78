// Counter-based RNG: deterministic, independent of evaluation order, statistically sound
// enough for perturbations (moments within 5 standard errors over 2^20 draws).
#include "core/hash_rng.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace morphogen::rng;

TEST(HashRng, DeterministicAndOrderFree) {
  const auto s = stream_id("params_alpha");
  EXPECT_EQ(hash(7, s, 12345), hash(7, s, 12345));
  EXPECT_NE(hash(7, s, 12345), hash(8, s, 12345));
  EXPECT_NE(hash(7, s, 12345), hash(7, stream_id("params_beta"), 12345));
  EXPECT_NE(hash(7, s, 12345), hash(7, s, 12346));
  EXPECT_EQ(stream_id("a"), stream_id(std::string("a")));
}

TEST(HashRng, UniformMoments) {
  const int n = 1 << 20;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = uniform(3, stream_id("u"), static_cast<std::uint64_t>(i));
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12.0 / n));
  EXPECT_NEAR(var, 1.0 / 12.0, 5 * std::sqrt(1.0 / 180.0 / n));
}

TEST(HashRng, GaussianMoments) {
  const int n = 1 << 20;
  double sum = 0, sum2 = 0, sum4 = 0;
  for (int i = 0; i < n; ++i) {
    const double g = gaussian(3, stream_id("g"), static_cast<std::uint64_t>(i));
    ASSERT_TRUE(std::isfinite(g));
    sum += g;
    sum2 += g * g;
    sum4 += g * g * g * g;
  }
  EXPECT_NEAR(sum / n, 0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(sum2 / n, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(sum4 / n, 3.0, 5 * std::sqrt(96.0 / n)); // kurtosis of a normal
}

TEST(HashRng, NeighbouringCellsUncorrelated) {
  const int n = 1 << 18;
  double c = 0;
  for (int i = 0; i < n; ++i)
    c += (uniform(1, 2, static_cast<std::uint64_t>(i)) - 0.5) *
         (uniform(1, 2, static_cast<std::uint64_t>(i + 1)) - 0.5);
  EXPECT_NEAR(c / n, 0.0, 5 * (1.0 / 12.0) / std::sqrt(n));
}
