// Stroke fields as values (strokes, strokes_directed, strokes_distance; fields/strokes_field.hpp):
// the field gathered from any number of ranks is bitwise the single-process one (every rank
// computes the whole x-y field; registered on 1, 2 and 4 ranks), a file named by several values
// is computed once, 3-D grids repeat the x-y field along z, and the grid limit is refused.
#include "../mpi_expect.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"
#include "fields/strokes_field.hpp"
#include "fields/strokes_file.hpp"
#include "io/slice_gather.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <unistd.h>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

// A stroke file written by rank 0 (name from rank 0's pid), removed by rank 0 at exit (after
// MPI_Finalize: no MPI calls in the destructor).
struct StrokeFile {
  std::string path;
  int rank = 0;
  explicit StrokeFile(const std::string& text) {
    int pid = static_cast<int>(getpid());
    MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
    MPI_Bcast(&pid, 1, MPI_INT, 0, PETSC_COMM_WORLD);
    path = "/tmp/morphogen_mpi_test_strokes_" + std::to_string(pid) + ".json";
    if (rank == 0) std::ofstream(path) << text;
    MPI_Barrier(PETSC_COMM_WORLD);
  }
  ~StrokeFile() {
    if (rank == 0) std::remove(path.c_str());
  }
};

// A spiral and a short straight stroke, in cells (a wall-bounded 61 x 47 grid, hx != hy).
const StrokeFile& file() {
  static const StrokeFile f([] {
    std::string s = R"({"units": "cells", "strokes": [{"points": [)";
    for (int k = 0; k <= 120; ++k) {
      const double t = 4 * M_PI * k / 120, r = 3 + 1.4 * t;
      s += (k ? ", [" : "[") + std::to_string(30 + r * std::cos(t)) + ", " +
           std::to_string(23 + r * std::sin(t)) + "]";
    }
    return s + R"(]}, {"points": [[2, 40], [12, 44]]}]})";
  }());
  return f;
}

GridSpec spec(int dim) {
  GridSpec s;
  s.dim = dim;
  s.n = {61, 47, dim == 3 ? 5 : 1};
  s.L = {6.1, 3.76, 1.0};
  s.bc = {Boundary::Neumann, Boundary::Neumann, Boundary::Neumann};
  return s;
}

// Field of `text` on comm, gathered (all z slices) on rank 0 of comm.
std::vector<double> field_on(MPI_Comm comm, int dim, const std::string& text) {
  Grid grid(comm, spec(dim));
  ValueSpec vs("tensor_a_theta", text, grid.spec(), 42);
  VecH v = grid.create_local();
  PetscScalar* a;
  VecGetArray(v, &a);
  fill_field(grid, vs, a, ArrayLayout::Ghosted, -1e300, 1e300);
  std::vector<double> all;
  for (PetscInt k = 0; k < grid.spec().n[2]; ++k) {
    auto s = io::gather_xy_slice(grid, a, k);
    all.insert(all.end(), s.begin(), s.end());
  }
  VecRestoreArray(v, &a);
  return all;
}

// The reference: the kernel driver on this process alone.
StrokeField reference(StrokeAngle mode) {
  const GridSpec s = spec(2);
  const FmmGrid g{61, 47, s.h(0), s.h(1), false, false};
  const std::string text = read_stroke_file_text(file().path);
  return compute_stroke_field(parse_strokes(file().path, text, s.L[0], s.L[1], g.hx, g.hy), g,
                              mode);
}

bool is_rank0() {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  return rank == 0;
}

} // namespace

TEST(Strokes, FieldIsBitwiseTheSameOnAnyRankCount) {
  const std::string q = "\"" + file().path + "\"";
  const auto theta = field_on(PETSC_COMM_WORLD, 2, "strokes(" + q + ")");
  const auto dirn = field_on(PETSC_COMM_WORLD, 2, "strokes_directed(" + q + ")");
  const auto dist = field_on(PETSC_COMM_WORLD, 2, "strokes_distance(" + q + ")");
  bool ok = true;
  if (is_rank0()) {
    const StrokeField a = reference(StrokeAngle::Axial), d = reference(StrokeAngle::Directed);
    const size_t bytes = a.theta.size() * sizeof(double);
    ok = theta.size() == a.theta.size() && std::memcmp(theta.data(), a.theta.data(), bytes) == 0 &&
         std::memcmp(dist.data(), a.distance.data(), bytes) == 0 &&
         std::memcmp(dirn.data(), d.theta.data(), bytes) == 0;
    // and it is a real field: angles over the whole range, distances from 0 up
    double lo = 1e9, hi = -1e9, dmax = 0;
    for (size_t c = 0; c < theta.size(); ++c) {
      lo = std::fmin(lo, theta[c]), hi = std::fmax(hi, theta[c]);
      dmax = std::fmax(dmax, dist[c]);
    }
    ok = ok && lo < -1.4 && hi > 1.4 && dmax > 0.5;
  }
  EXPECT_TRUE(all_ranks(ok));
  EXPECT_TRUE(
      all_ranks(!is_rank0() || field_on(PETSC_COMM_SELF, 2, "strokes(" + q + ")") == theta));
}

TEST(Strokes, ThreeDimensionsRepeatTheXyField) {
  const std::string q = "\"" + file().path + "\"";
  const auto f3 = field_on(PETSC_COMM_WORLD, 3, "strokes_distance(" + q + ") + strokes(" + q + ")");
  const auto f2 = field_on(PETSC_COMM_WORLD, 2, "strokes_distance(" + q + ") + strokes(" + q + ")");
  bool ok = true;
  if (is_rank0()) {
    ok = f3.size() == 5 * f2.size();
    for (size_t k = 0; ok && k < 5; ++k)
      ok = std::memcmp(f3.data() + k * f2.size(), f2.data(), f2.size() * sizeof(double)) == 0;
  }
  EXPECT_TRUE(all_ranks(ok));
}

TEST(Strokes, AFileIsComputedOncePerGrid) {
  const GridSpec s = spec(2);
  const FmmGrid g{61, 47, s.h(0), s.h(1), false, false};
  const auto a = cached_stroke_field(file().path, g, StrokeAngle::Axial);
  const auto b = cached_stroke_field(file().path, g, StrokeAngle::Axial);
  EXPECT_EQ(a.get(), b.get());
  const FmmGrid g2{62, 47, s.h(0), s.h(1), false, false};
  EXPECT_NE(cached_stroke_field(file().path, g2, StrokeAngle::Axial).get(), a.get());
}

TEST(Strokes, GridOverTheLimitIsRefused) {
  GridSpec s = spec(2);
  s.n = {4097, 4096, 1};
  std::string msg;
  try {
    ValueSpec vs("tensor_a_theta", "strokes(\"" + file().path + "\")", s, 1);
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("-tensor_a_theta"), std::string::npos) << msg;
  EXPECT_NE(msg.find("4096^2"), std::string::npos) << msg;
}
