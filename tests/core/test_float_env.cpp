// Subnormal flushing (core/float_env.hpp): on, a product below 2.2e-308 is zero and a subnormal
// input counts as zero; off, IEEE gradual underflow. The state is the thread's own and is read
// back by flush_subnormals().
#include "core/float_env.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace morphogen;

namespace {
double product(double a, double b) {
  volatile double x = a, y = b; // no constant folding: the CPU's mode decides
  return x * y;
}
double sum(double a, double b) {
  volatile double x = a, y = b;
  return x + y;
}
} // namespace

TEST(FloatEnv, FlushOnGivesZeroForSubnormalResultsAndInputs) {
  ASSERT_TRUE(set_flush_subnormals(true)); // x86-64 and AArch64 have the control
  EXPECT_TRUE(flush_subnormals());
  EXPECT_EQ(product(1e-300, 1e-10), 0.0);
  const double sub = std::numeric_limits<double>::denorm_min() * 1000;
  EXPECT_EQ(sum(sub, 0.0), 0.0);
  EXPECT_EQ(product(1e-300, 1e-5), 1e-300 * 1e-5); // normal results are untouched
  set_flush_subnormals(false);
}

TEST(FloatEnv, FlushOffKeepsGradualUnderflow) {
  set_flush_subnormals(false);
  EXPECT_FALSE(flush_subnormals());
  const double p = product(1e-300, 1e-10);
  EXPECT_EQ(std::fpclassify(p), FP_SUBNORMAL);
  EXPECT_NEAR(p, 1e-310, 1e-315);
}
