// Block means for quick-look images (io/block_mean_kernel.hpp): a known pattern reduced equals
// its block means (independent double reference, tolerance the quantisation bound (hi-lo)
// 2^-40), edge blocks average the cells they hold, non-finite cells mark their block NaN, and
// the integer sums do not depend on how rows are split or in which order they arrive.
#include "io/block_mean_kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

using namespace morphogen::io;

namespace {

double pattern(long long i, long long j) {
  return std::sin(0.37 * static_cast<double>(i)) + 0.01 * static_cast<double>(j * j) - 3.0;
}

// Block sums of an nx x ny pattern, rows added whole in increasing j.
std::vector<BlockSum> reduce(const BlockMeanPlan& p) {
  std::vector<BlockSum> s(static_cast<size_t>(p.w * p.h));
  std::vector<double> row(static_cast<size_t>(p.nx));
  for (long long j = 0; j < p.ny; ++j) {
    for (long long i = 0; i < p.nx; ++i)
      row[i] = pattern(i, j);
    add_row_to_blocks(p, j, 0, p.nx, row.data(), 0, 0, p.w, s.data());
  }
  return s;
}

BlockMeanPlan plan_for(long long nx, long long ny, long long max_size) {
  double lo = INFINITY, hi = -INFINITY;
  for (long long j = 0; j < ny; ++j)
    for (long long i = 0; i < nx; ++i) {
      lo = std::min(lo, pattern(i, j));
      hi = std::max(hi, pattern(i, j));
    }
  return block_mean_plan(nx, ny, max_size, lo, hi);
}

} // namespace

TEST(BlockMean, Factor) {
  EXPECT_EQ(block_factor(4096, 4096, 1024), 4);
  EXPECT_EQ(block_factor(1024, 1024, 1024), 1); // fits: unchanged
  EXPECT_EQ(block_factor(1025, 10, 1024), 2);
  EXPECT_EQ(block_factor(4096, 4096, 0), 1); // 0: off
  EXPECT_EQ(block_factor(10, 7, 4), 3);
  const BlockMeanPlan p = block_mean_plan(10, 7, 4, 0.0, 1.0);
  EXPECT_EQ(p.w, 4); // ceil(10 / 3)
  EXPECT_EQ(p.h, 3); // ceil(7 / 3)
}

TEST(BlockMean, EqualsTheBlockMeanOfAKnownPattern) {
  const long long nx = 10, ny = 7;
  const BlockMeanPlan p = plan_for(nx, ny, 4); // f = 3: edge blocks of 1 column / 1 row
  const auto s = reduce(p);
  const double tol = 1.0 / p.scale + 1e-14; // one quantum, (hi - lo) 2^-40, plus rounding
  for (long long J = 0; J < p.h; ++J)
    for (long long I = 0; I < p.w; ++I) {
      double sum = 0;
      int n = 0;
      for (long long j = 3 * J; j < std::min(3 * J + 3, ny); ++j)
        for (long long i = 3 * I; i < std::min(3 * I + 3, nx); ++i, ++n)
          sum += pattern(i, j);
      const BlockSum& b = s[static_cast<size_t>(I + p.w * J)];
      EXPECT_EQ(b.count, n);
      EXPECT_NEAR(block_mean(p, b), sum / n, tol) << "block " << I << "," << J;
    }
  // The bound is real: far below the pattern's cell-to-cell differences (~0.1).
  EXPECT_LT(tol, 1e-11);
}

TEST(BlockMean, SameSumsForAnySplitAndOrder) {
  const BlockMeanPlan p = plan_for(23, 17, 5); // f = 5
  const auto whole = reduce(p);
  // Rows in reverse order, each split into segments at arbitrary columns (as ranks would hold
  // them), added into a sub-rectangle of blocks and then summed into the image.
  std::vector<BlockSum> split(whole.size());
  const long long cuts[] = {0, 4, 11, 12, 23};
  for (long long j = p.ny - 1; j >= 0; --j)
    for (int c = 3; c >= 0; --c) {
      const long long i0 = cuts[c], n = cuts[c + 1] - cuts[c];
      std::vector<double> row(static_cast<size_t>(n));
      for (long long i = 0; i < n; ++i)
        row[i] = pattern(i0 + i, j);
      const long long bx0 = i0 / p.f, bw = (i0 + n - 1) / p.f - bx0 + 1;
      std::vector<BlockSum> part(static_cast<size_t>(bw));
      add_row_to_blocks(p, j, i0, n, row.data(), bx0, j / p.f, bw, part.data());
      for (long long b = 0; b < bw; ++b) {
        BlockSum& t = split[static_cast<size_t>(bx0 + b + p.w * (j / p.f))];
        t.q += part[b].q;
        t.count += part[b].count;
        t.bad += part[b].bad;
      }
    }
  for (size_t b = 0; b < whole.size(); ++b) {
    const double a = block_mean(p, whole[b]), c = block_mean(p, split[b]);
    EXPECT_EQ(std::memcmp(&a, &c, sizeof a), 0) << "block " << b;
  }
}

TEST(BlockMean, NonFiniteAndConstantFields) {
  BlockMeanPlan p = block_mean_plan(4, 2, 2, 1.5, 1.5); // f = 2, constant field
  std::vector<BlockSum> s(2);
  const double row[4] = {1.5, 1.5, NAN, 1.5};
  add_row_to_blocks(p, 0, 0, 4, row, 0, 0, 2, s.data());
  EXPECT_EQ(block_mean(p, s[0]), 1.5); // hi == lo: exactly lo
  EXPECT_TRUE(std::isnan(block_mean(p, s[1])));
  EXPECT_TRUE(std::isnan(block_mean(p, BlockSum{}))); // no cell
}
