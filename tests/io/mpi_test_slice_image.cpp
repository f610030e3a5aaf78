// Reduced slice images (io/slice_image.hpp) gathered from a distributed field: the image is
// bitwise the same on every rank count (world vs a one-rank reference, run on 1, 2 and 4
// ranks), equals the block means of a known pattern (independent double sums, tolerance one
// quantum (hi - lo) 2^-40), the range is the full-resolution min/max, and a slice that fits
// is returned unreduced.
#include "../mpi_expect.hpp"
#include "io/slice_image.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

double pattern(PetscInt i, PetscInt j, PetscInt k) {
  return std::cos(0.21 * static_cast<double>(i)) * std::sin(0.13 * static_cast<double>(j)) +
         1e-3 * static_cast<double>((i * 7919 + j * 104729 + k * 31) % 1000);
}

GridSpec spec(std::array<PetscInt, 3> n, int dim) {
  GridSpec s;
  s.dim = dim;
  s.n = n;
  s.L = {1.0, 1.0, 1.0};
  return s;
}

// The image of the pattern on comm (rank 0 of comm holds it).
io::SliceImage image_on(MPI_Comm comm, const GridSpec& gs, long long max_size) {
  Grid grid(comm, gs);
  VecH v = grid.create_local();
  PetscScalar* a;
  VecGetArray(v, &a);
  const Box& ob = grid.owned();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        a[grid.local_index(i, j, k)] = pattern(i, j, k);
  const PetscInt kz = gs.dim == 3 ? gs.n[2] / 2 : 0;
  io::SliceImage img = io::gather_xy_slice_image(grid, a, kz, max_size);
  VecRestoreArray(v, &a);
  return img;
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

void expect_block_means(const GridSpec& gs, long long max_size, long long f) {
  const io::SliceImage w = image_on(PETSC_COMM_WORLD, gs, max_size);
  const io::SliceImage s = image_on(PETSC_COMM_SELF, gs, max_size);
  bool ok = true;
  if (world_rank() == 0) {
    ASSERT_EQ(w.factor, f);
    ASSERT_EQ(w.width, (gs.n[0] + f - 1) / f);
    ASSERT_EQ(w.height, (gs.n[1] + f - 1) / f);
    ASSERT_EQ(w.value.size(), static_cast<size_t>(w.width) * w.height);
    // Rank independence: bitwise the one-rank image.
    ok = w.value.size() == s.value.size() &&
         std::memcmp(w.value.data(), s.value.data(), w.value.size() * sizeof(double)) == 0 &&
         w.lo == s.lo && w.hi == s.hi;
    EXPECT_TRUE(ok) << "image differs from the one-rank image";
    const PetscInt kz = gs.dim == 3 ? gs.n[2] / 2 : 0;
    double lo = INFINITY, hi = -INFINITY;
    for (PetscInt j = 0; j < gs.n[1]; ++j)
      for (PetscInt i = 0; i < gs.n[0]; ++i) {
        lo = std::min(lo, pattern(i, j, kz));
        hi = std::max(hi, pattern(i, j, kz));
      }
    EXPECT_EQ(w.lo, lo);
    EXPECT_EQ(w.hi, hi);
    const double tol = (hi - lo) * std::ldexp(1.0, -40) + 1e-14;
    for (int J = 0; J < w.height; ++J)
      for (int I = 0; I < w.width; ++I) {
        double sum = 0;
        int n = 0;
        for (PetscInt j = J * f; j < std::min<PetscInt>(J * f + f, gs.n[1]); ++j)
          for (PetscInt i = I * f; i < std::min<PetscInt>(I * f + f, gs.n[0]); ++i, ++n)
            sum += pattern(i, j, kz);
        EXPECT_NEAR(w.value[I + static_cast<size_t>(w.width) * J], sum / n, tol)
            << "pixel " << I << "," << J;
      }
  }
  EXPECT_TRUE(all_ranks(ok));
}

} // namespace

TEST(SliceImage, BlockMeansOnAnyRankCount2D) {
  expect_block_means(spec({64, 48, 1}, 2), 16, 4); // blocks aligned to 4
  expect_block_means(spec({37, 23, 1}, 2), 8, 5);  // uneven: edge blocks, blocks across ranks
}

TEST(SliceImage, BlockMeansOfTheMiddleSlice3D) {
  expect_block_means(spec({21, 18, 6}, 3), 7, 3);
}

TEST(SliceImage, FittingSliceIsUnreduced) {
  const GridSpec gs = spec({30, 20, 1}, 2);
  for (long long max_size : {0LL, 30LL, 1024LL}) {
    const io::SliceImage w = image_on(PETSC_COMM_WORLD, gs, max_size);
    if (world_rank() != 0) continue;
    ASSERT_EQ(w.factor, 1);
    ASSERT_EQ(w.width, 30);
    ASSERT_EQ(w.height, 20);
    for (PetscInt j = 0; j < 20; ++j)
      for (PetscInt i = 0; i < 30; ++i)
        ASSERT_EQ(w.value[i + 30 * j], pattern(i, j, 0));
  }
}
