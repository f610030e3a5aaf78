// Value specifications evaluated into fields: random fields identical on 1 and N ranks
// (hash of seed, key and global cell index), perturbation bounds and statistics, expression
// variables, shapes, and every error path naming the key.
#include "../mpi_expect.hpp"
#include "core/user_error.hpp"
#include "fields/field_fill.hpp"
#include "io/png_file.hpp"
#include "io/slice_gather.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <unistd.h>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

GridSpec spec(int dim) {
  GridSpec s;
  s.dim = dim;
  s.n = dim == 2 ? std::array<PetscInt, 3>{37, 29, 1} : std::array<PetscInt, 3>{13, 11, 9};
  s.L = {3.7, 2.9, 0.9};
  return s;
}

// Field of `text` on comm, gathered (all z slices) on rank 0 of comm.
std::vector<double> field_on(MPI_Comm comm, int dim, const std::string& text) {
  Grid grid(comm, spec(dim));
  ValueSpec vs("init_a", text, grid.spec(), 42);
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

bool same_on_world_and_self(int dim, const std::string& text) {
  const auto w = field_on(PETSC_COMM_WORLD, dim, text);
  const auto s = field_on(PETSC_COMM_SELF, dim, text);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  bool ok = true;
  if (rank == 0) {
    ok = w.size() == s.size() && std::memcmp(w.data(), s.data(), w.size() * sizeof(double)) == 0;
    // and it is really random: not all cells equal
    ok = ok && w.size() > 2 && w[0] != w[1];
  }
  return all_ranks(ok);
}

std::string error_of(const std::string& key, const std::string& text) {
  try {
    ValueSpec vs(key, text, spec(2), 1);
    vs.at_cell(0, 0, 0);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(RandomFields, IdenticalOnAnyRankCount2D) {
  EXPECT_TRUE(same_on_world_and_self(2, "12 +- 0.1% gauss"));
  EXPECT_TRUE(same_on_world_and_self(2, "noise() + gnoise()"));
  EXPECT_TRUE(same_on_world_and_self(2, "4 +- 1"));
}

TEST(RandomFields, IdenticalOnAnyRankCount3D) {
  EXPECT_TRUE(same_on_world_and_self(3, "16 +- 0.5% gauss"));
  EXPECT_TRUE(same_on_world_and_self(3, "1 + spots(5, 0.3, 7) +- 2%"));
}

TEST(ValueSpec, ConstantsAreScalars) {
  ValueSpec a("params_s", "1/128", spec(2), 1);
  EXPECT_TRUE(a.is_constant());
  EXPECT_DOUBLE_EQ(a.constant_value(), 1.0 / 128);
  ValueSpec b("params_s", "2*pi", spec(2), 1);
  EXPECT_TRUE(b.is_constant());
  ValueSpec c("params_s", "x", spec(2), 1);
  EXPECT_FALSE(c.is_constant());
  ValueSpec d("params_s", "1 +- 1%", spec(2), 1);
  EXPECT_FALSE(d.is_constant());
  ValueSpec e("params_s", "noise()", spec(2), 1);
  EXPECT_FALSE(e.is_constant());
}

TEST(ValueSpec, VariablesAtCellCentres) {
  ValueSpec v("k", "x + 10*y + 100*i + 1000*j + Lx*nx", spec(2), 1);
  // cell (2,3): x = 2.5*0.1, y = 3.5*0.1
  EXPECT_NEAR(v.at_cell(2, 3, 0), 0.25 + 3.5 + 200 + 3000 + 3.7 * 37, 1e-12);
  ValueSpec r("k", "r", spec(2), 1);
  EXPECT_NEAR(r.at_cell(18, 14, 0), std::hypot(18.5 * 0.1 - 1.85, 14.5 * 0.1 - 1.45), 1e-12);
  ValueSpec th("k", "theta", spec(2), 1);
  EXPECT_NEAR(th.at_cell(30, 14, 0), std::atan2(14.5 * 0.1 - 1.45, 30.5 * 0.1 - 1.85), 1e-12);
}

TEST(ValueSpec, Shapes) {
  ValueSpec sq("k", "square(1.85, 1.45, 0.3)", spec(2), 1);
  EXPECT_EQ(sq.at_cell(18, 14, 0), 1.0);
  EXPECT_EQ(sq.at_cell(18, 20, 0), 0.0);
  ValueSpec dk("k", "disk(0.05, 0.05, 0.2)", spec(2), 1); // periodic: wraps around corners
  EXPECT_EQ(dk.at_cell(0, 0, 0), 1.0);
  EXPECT_EQ(dk.at_cell(36, 28, 0), 1.0);
  EXPECT_EQ(dk.at_cell(18, 14, 0), 0.0);
  ValueSpec sp("k", "spots(20, 0.2, 3)", spec(2), 1);
  int inside = 0;
  for (int j = 0; j < 29; ++j)
    for (int i = 0; i < 37; ++i)
      inside += sp.at_cell(i, j, 0) > 0.5;
  EXPECT_GT(inside, 20);
  EXPECT_LT(inside, 37 * 29);
}

TEST(ValueSpec, PerturbationBoundsAndMoments) {
  ValueSpec u("params_alpha", "12 +- 0.1%", spec(2), 5);
  ValueSpec g("params_beta", "16 +- 0.5 gauss", spec(2), 5);
  double gs = 0, gs2 = 0;
  const int n = 37 * 29;
  for (int j = 0; j < 29; ++j)
    for (int i = 0; i < 37; ++i) {
      const double a = u.at_cell(i, j, 0);
      EXPECT_GE(a, 12 * 0.999);
      EXPECT_LE(a, 12 * 1.001);
      const double b = g.at_cell(i, j, 0) - 16;
      gs += b, gs2 += b * b;
    }
  EXPECT_NEAR(gs / n, 0.0, 5 * 0.5 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(gs2 / n), 0.5, 0.05);
}

TEST(ValueSpec, PngMappedOntoRange) {
  char dir[] = "/tmp/morphogen_vs_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/ramp.png";
  // 2x1 image: black left, white right.
  const unsigned char rgb[6] = {0, 0, 0, 255, 255, 255};
  io::write_png_rgb(path, 2, 1, rgb);
  ValueSpec v("params_alpha", "png(\"ramp.png\", 17.5, 27.5)", spec(2), 1, dir);
  EXPECT_NEAR(v.at_point(0.0, 1.0, 0, 0, 0, 0), 17.5, 1e-12);
  EXPECT_NEAR(v.at_point(3.7, 1.0, 0, 0, 0, 0), 27.5, 1e-12);
  EXPECT_NEAR(v.at_point(1.85, 1.0, 0, 0, 0, 0), 22.5, 1e-12);
  std::remove(path.c_str());
  rmdir(dir);
}

TEST(ValueSpec, ErrorsNameTheKey) {
  EXPECT_NE(error_of("params_alpha", "12 +* x").find("-params_alpha 12 +* x: "), std::string::npos);
  EXPECT_NE(error_of("init_a", "4 + w").find("-init_a"), std::string::npos);
  EXPECT_NE(error_of("init_a", "1/0").find("evaluates to inf"), std::string::npos);
  EXPECT_NE(error_of("init_a", "sqrt(-1)").find("-init_a"), std::string::npos);
  EXPECT_NE(error_of("init_a", "4 +- x%").find("bad perturbation"), std::string::npos);
  EXPECT_NE(error_of("init_a", "").find("empty"), std::string::npos);
  EXPECT_NE(
      error_of("params_alpha", "png(\"/nonexistent/p.png\", 0, 1)").find("/nonexistent/p.png"),
      std::string::npos);
}

// Rows (fill_row: the bytecode over columns where the expression allows it) are bitwise the
// cell-by-cell values (at_cell), for muParser operators and functions of every variable, with
// and without perturbations, expressions with cell functions, in 2-D and 3-D, from any first
// cell; a value that is not finite names its cell.
TEST(ValueSpec, RowsAreBitwiseTheCells) {
  const char* texts[] = {"12 + 0.5*sin(x/17)*cos(y/13)",
                         "x + 10*y + 100*i + 1000*j + 3*z + k",
                         "exp(-r^2/4) + 0.1*theta + t^2",
                         "x^2 + x^3 + x^4 - 2*y*x + min(x, y, 1.5) + (x > 1 ? 2 : 3)",
                         "4 + 0.5*atan2(y - 1, x - 2) +- 1% gauss",
                         "16 + sum(x, y, z) +- 0.2",
                         "1 + disk(1, 1, 0.5)",
                         "1 + noise()",
                         "3 +- 1%",
                         "7"};
  for (int dim : {2, 3})
    for (const char* text : texts) {
      SCOPED_TRACE(std::string(text) + " dim " + std::to_string(dim));
      ValueSpec cells("init_a", text, spec(dim), 7), rows("init_a", text, spec(dim), 7);
      const GridSpec g = spec(dim);
      for (PetscInt k = 0; k < g.n[2]; ++k)
        for (PetscInt j = 0; j < g.n[1]; ++j)
          for (PetscInt i0 : {PetscInt(0), PetscInt(5)}) {
            const PetscInt n = g.n[0] - i0;
            std::vector<double> row(static_cast<size_t>(n));
            rows.fill_row(i0, n, j, k, 0.75, row.data());
            for (PetscInt q = 0; q < n; ++q)
              ASSERT_EQ(row[static_cast<size_t>(q)], cells.at_cell(i0 + q, j, k, 0.75))
                  << "cell " << i0 + q << "," << j << "," << k;
          }
    }
  ValueSpec bad("init_a", "1/(x - 0.05)", spec(2), 1); // x = 0.05 at cell 0 (h = 0.1)
  std::vector<double> row(37);
  std::string msg;
  try {
    bad.fill_row(0, 37, 3, 0, 0.0, row.data());
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("evaluates to inf at cell (0,3,0)"), std::string::npos) << msg;
}

TEST(FieldFill, RangeViolationIsCollective) {
  // The violation lies in the last cells only (one rank's part on 2 ranks); every rank throws.
  Grid grid(PETSC_COMM_WORLD, spec(2));
  ValueSpec vs("params_alpha", "j > 27 ? -1 : 12", grid.spec(), 1);
  VecH v = grid.create_global();
  PetscScalar* a;
  VecGetArray(v, &a);
  bool threw = false;
  std::string msg;
  try {
    fill_field(grid, vs, a, ArrayLayout::Owned, 0, 1e6);
  } catch (const UserError& e) {
    threw = true;
    msg = e.what();
  }
  VecRestoreArray(v, &a);
  EXPECT_TRUE(all_ranks(threw));
  EXPECT_NE(msg.find("outside the allowed range"), std::string::npos) << msg;
}
