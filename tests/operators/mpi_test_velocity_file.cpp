// Advection velocity from HDF5 files (fields/velocity_file.hpp, -velocity_file) against the
// same velocity given as expressions (-velocity_x/_y/_z), pure transport (custom model, rate 0,
// D 0) with Courant numbers above a rank's extent (back-traces crossing ranks):
// (1) steady, 2-D: the file written here (serial HDF5 C API on rank 0, not morphogen's reader or
//     writer) holds the expression's values at the cell centres, chosen exactly representable
//     (dyadic), as (1, ny, nx) datasets in /VTKHDF/PointData: the final state is bitwise equal
//     to the expression run's;
// (2) steady, 3-D, flat datasets /u, /v, /w (a VTKHDF cell-array layout of another writer,
//     named by -velocity_datasets): bitwise equal;
// (3) a two-frame .series with a velocity linear in t, u(t) = u0 (1 + t/2), frames at t = 0 and
//     4: equal to the expression 0.25*(y-16)*(1 + 0.5*t) to round-off (1e-12; the time
//     interpolation and the expression round differently);
// (4) frames at t = -1 and 0 (a comma list with -velocity_times): the run (t > 0) holds the
//     last frame, bitwise equal to a steady run with that frame;
// (5) every file case on PETSC_COMM_WORLD against the same on PETSC_COMM_SELF: bitwise equal
//     (1, 2 and 4 ranks).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "core/options.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <unistd.h>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

using Field = std::function<double(double x, double y, double z)>;

// A directory unique to this test process group (rank 0's pid), removed by the caller.
std::string scratch_dir() {
  int pid = static_cast<int>(getpid());
  MPI_Bcast(&pid, 1, MPI_INT, 0, PETSC_COMM_WORLD);
  const auto dir =
      std::filesystem::temp_directory_path() / ("mg_velocity_file_" + std::to_string(pid));
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) std::filesystem::create_directories(dir);
  MPI_Barrier(PETSC_COMM_WORLD);
  return dir.string();
}

// Writes datasets `paths` (values of `fields` at the cell centres of an n-cell grid with
// spacing 1, x fastest) with extents `dims` into a new file, on rank 0.
void write_file(const std::string& file, const std::vector<std::string>& paths,
                const std::vector<Field>& fields, const std::array<int, 3>& n,
                const std::vector<hsize_t>& dims) {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank == 0) {
    const hid_t f = H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(lcpl, 1);
    for (size_t a = 0; a < paths.size(); ++a) {
      std::vector<double> v;
      for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
            v.push_back(fields[a](i + 0.5, j + 0.5, k + 0.5));
      const hid_t sp = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
      const hid_t ds =
          H5Dcreate2(f, paths[a].c_str(), H5T_IEEE_F64LE, sp, lcpl, H5P_DEFAULT, H5P_DEFAULT);
      H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
      H5Dclose(ds);
      H5Sclose(sp);
    }
    H5Pclose(lcpl);
    H5Fclose(f);
  }
  MPI_Barrier(PETSC_COMM_WORLD);
}

// The final state of `opts` on comm, gathered on its rank 0.
std::vector<double> final_state(MPI_Comm comm, const OptionList& opts, int steps) {
  auto sim = make_sim(comm, opts);
  for (int s = 0; s < steps; ++s)
    sim->step();
  return gather_all(sim->grid(), sim->state()[0]);
}

bool rank0() {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  return rank == 0;
}

double max_diff(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return INFINITY;
  double m = 0;
  for (size_t c = 0; c < a.size(); ++c)
    m = std::max(m, std::fabs(a[c] - b[c]));
  return m;
}

// Not vacuous: finite values that vary.
bool varies(const std::vector<double>& a) {
  if (a.empty()) return !rank0();
  const auto [lo, hi] = std::minmax_element(a.begin(), a.end());
  return std::all_of(a.begin(), a.end(), [](double v) { return std::isfinite(v); }) &&
         *hi - *lo > 1e-2;
}

// `file_opts` against `expr_opts` (max difference <= tol on rank 0; 0: bitwise), and the file
// run on the world against the same on PETSC_COMM_SELF (bitwise).
void expect_equal_runs(const OptionList& file_opts, const OptionList& expr_opts, int steps,
                       double tol, const char* what) {
  const auto file = final_state(PETSC_COMM_WORLD, file_opts, steps);
  const auto expr = final_state(PETSC_COMM_WORLD, expr_opts, steps);
  const auto self = final_state(PETSC_COMM_SELF, file_opts, steps);
  const double d = rank0() ? max_diff(file, expr) : 0.0;
  const bool same_self =
      !rank0() || (file.size() == self.size() &&
                   std::memcmp(file.data(), self.data(), file.size() * sizeof(double)) == 0);
  PetscPrintf(PETSC_COMM_WORLD, "  %s: file vs expressions max |diff| = %.3g; %d rank(s) vs 1 %s\n",
              what, d, comm_size(), same_self ? "bitwise identical" : "DIFFERENT");
  EXPECT_TRUE(all_ranks(varies(file))) << what;
  EXPECT_TRUE(all_ranks(tol == 0 ? d == 0 : d <= tol)) << what << ": " << d;
  EXPECT_TRUE(all_ranks(same_self)) << what;
}

OptionList transport_2d() {
  return {{"model", "custom"},
          {"species", "a"},
          {"rate_a", "0"},
          {"D_a", "0"},
          {"grid_n", "32,32"},
          {"grid_L", "32"},
          {"grid_bc", "periodic,neumann"},
          {"init_a", "exp(-((x-12)^2 + (y-16)^2)/18)"},
          {"dt", "0.5"},
          {"advect", "a"},
          {"summary", "false"}};
}

OptionList with(OptionList o, const OptionList& more) {
  o.insert(o.end(), more.begin(), more.end());
  return o;
}

const Field kShearX = [](double, double y, double) { return 0.25 * (y - 16); };
const Field kShearY = [](double x, double, double) { return 0.125 * (x - 16); };

} // namespace

TEST(VelocityFile, SteadyEqualsExpressions) {
  const std::string dir = scratch_dir();
  const std::string file = dir + "/steady.h5";
  write_file(file, {"/VTKHDF/PointData/velocity_x", "/VTKHDF/PointData/velocity_y"},
             {kShearX, kShearY}, {32, 32, 1}, {1, 32, 32});
  for (const char* scheme : {"linear", "cubic"}) {
    const OptionList base = with(transport_2d(), {{"advection_scheme", scheme}});
    expect_equal_runs(with(base, {{"velocity_file", file}}),
                      with(base, {{"velocity_x", "0.25*(y-16)"}, {"velocity_y", "0.125*(x-16)"}}),
                      10, 0.0, scheme);
  }
  if (rank0()) std::filesystem::remove_all(dir);
}

TEST(VelocityFile, Steady3dFlatDatasets) {
  const std::string dir = scratch_dir();
  const std::string file = dir + "/flat3d.h5";
  write_file(file, {"/u", "/v", "/w"},
             {[](double, double y, double) { return -(y - 5); },
              [](double x, double, double) { return x - 6; },
              [](double, double, double z) { return 4 + z; }},
             {12, 10, 8}, {12 * 10 * 8});
  const OptionList base = {{"model", "custom"},      {"species", "a"},
                           {"rate_a", "0"},          {"D_a", "0"},
                           {"grid_n", "12,10,8"},    {"grid_bc", "neumann,periodic,dirichlet"},
                           {"init_a", "0.5 +- 40%"}, {"dt", "0.5"},
                           {"advect", "a"},          {"summary", "false"}};
  expect_equal_runs(
      with(base, {{"velocity_file", file}, {"velocity_datasets", "/u,/v,/w"}}),
      with(base, {{"velocity_x", "-(y-5)"}, {"velocity_y", "(x-6)"}, {"velocity_z", "4 + z"}}), 6,
      0.0, "3-D flat");
  if (rank0()) std::filesystem::remove_all(dir);
}

TEST(VelocityFile, SeriesLinearInTime) {
  const std::string dir = scratch_dir();
  // Frames at t = 0 and 4 of u(t) = u0 (1 + t/2): u0 and 3 u0.
  write_file(dir + "/f0.h5", {"velocity_x", "velocity_y"}, {kShearX, kShearY}, {32, 32, 1},
             {32, 32});
  write_file(dir + "/f1.h5", {"velocity_x", "velocity_y"},
             {[](double x, double y, double z) { return 3 * kShearX(x, y, z); },
              [](double x, double y, double z) { return 3 * kShearY(x, y, z); }},
             {32, 32, 1}, {32, 32});
  if (rank0()) {
    FILE* f = std::fopen((dir + "/v.series").c_str(), "w");
    std::fprintf(f, "{\"file-series-version\": \"1.0\", \"files\": [{\"name\": \"f0.h5\", "
                    "\"time\": 0}, {\"name\": \"f1.h5\", \"time\": 4}]}\n");
    std::fclose(f);
  }
  MPI_Barrier(PETSC_COMM_WORLD);
  // 8 steps of 0.5: t + dt/2 from 0.25 to 3.75, inside the frames.
  // The expression run sizes its halo from the start's velocity: give both the file's (from the
  // fastest frame, Courant 5.8).
  const OptionList base = with(transport_2d(), {{"advection_halo", "8"}});
  expect_equal_runs(with(base, {{"velocity_file", dir + "/v.series"}}),
                    with(base, {{"velocity_x", "0.25*(y-16)*(1 + 0.5*t)"},
                                {"velocity_y", "0.125*(x-16)*(1 + 0.5*t)"}}),
                    8, 1e-12, "two-frame series, linear in t");
  // Frames at t = -1 (3 u0) and 0 (u0): every step is after the last frame, which is held.
  expect_equal_runs(
      with(base, {{"velocity_file", dir + "/f1.h5," + dir + "/f0.h5"}, {"velocity_times", "-1,0"}}),
      with(base, {{"velocity_file", dir + "/f0.h5"}}), 8, 0.0, "after the last frame: held");
  if (rank0()) std::filesystem::remove_all(dir);
}
