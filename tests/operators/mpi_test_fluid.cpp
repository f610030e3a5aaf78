// The 2-D stable-fluids solver (operators/fluid_solver.hpp):
// (1) projection: the corrected face velocities are divergence-free to the KSP tolerance (to
//     round-off where the pressure is solved by FFT/DCT: cavity, periodic)
//     (||div||_2 after / before <= rtol = 1e-8, the unpreconditioned residual), on a cavity, a
//     channel with an obstacle and a periodic square;
// (2) projection of u = curl(psi) + grad(phi) on a periodic square recovers curl(psi) with
//     second-order error (the cell-centred approximate projection): error at 32^2 and 64^2,
//     observed order >= 1.8;
// (3) lid-driven cavity at Re = 100 (U = 1, L = 1, nu = 0.01) at 64^2, integrated to t = 12
//     (steady state), against Ghia, Ghia & Shin, J. Comput. Phys. 48 (1982) 387-411, Table I
//     (u on the vertical centre-line): max |u - u_Ghia| over the 17 published points <= 0.03
//     (2-3 % of U; the 64^2 grid with linear semi-Lagrangian self-advection);
// (4) a solid obstacle (disc) in the channel: zero velocity inside, through-flow U preserved;
// (5) rank-count independence: the cavity velocity after 20 steps on PETSC_COMM_WORLD equals
//     the same run on PETSC_COMM_SELF to 1e-7 (the KSP tolerances), on 1, 2 and 4 ranks.
#include "../mpi_expect.hpp"

#include "io/slice_gather.hpp"
#include "operators/fluid_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

const double kPi = 3.14159265358979323846;

std::unique_ptr<Grid> make_grid(MPI_Comm comm, int n, bool periodic) {
  GridSpec g;
  g.dim = 2;
  g.n = {n, n, 1};
  g.L = {1.0, 1.0, 1.0};
  const Boundary b = periodic ? Boundary::Periodic : Boundary::Neumann;
  g.bc = {b, b, Boundary::Periodic};
  return std::make_unique<Grid>(comm, g);
}

// Solid mask of owned cells from f(x, y) (true: solid).
std::vector<double> mask(const Grid& grid, const std::function<bool(double, double)>& f) {
  std::vector<double> m(static_cast<size_t>(grid.owned().size()), 0.0);
  const Box& ob = grid.owned();
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      m[static_cast<size_t>(grid.owned_index(i, j, 0))] =
          f(grid.centre(0, i), grid.centre(1, j)) ? 1.0 : 0.0;
  return m;
}

std::vector<double> gather(const Grid& grid, Vec local) {
  const PetscScalar* a;
  VecGetArrayRead(local, &a);
  auto s = io::gather_xy_slice(grid, a, 0);
  VecRestoreArrayRead(local, &a);
  return s;
}

FluidSettings cavity(double nu) {
  FluidSettings s;
  s.kind = fluid::Kind::Cavity;
  s.viscosity = nu;
  s.lid = 1.0;
  return s;
}

auto none = [](double, double) { return false; };

// A random-looking smooth field to project.
void wavy(double x, double y, double& u, double& v) {
  u = std::sin(3 * x + 1) * std::cos(2 * y) + 0.3 * x;
  v = std::cos(5 * x * y) - y * y;
}

} // namespace

TEST(Fluid, ProjectionIsDivergenceFreeToSolverTolerance) {
  for (int kind = 0; kind < 3; ++kind) {
    auto grid = make_grid(PETSC_COMM_WORLD, 48, kind == 2);
    FluidSettings s = cavity(0.01);
    s.kind = static_cast<fluid::Kind>(kind);
    auto disc = [](double x, double y) { return std::hypot(x - 0.3, y - 0.5) < 0.1; };
    FluidSolver f(*grid, s,
                  mask(*grid, kind == 1 ? std::function<bool(double, double)>(disc)
                                        : std::function<bool(double, double)>(none)));
    f.set_velocity(wavy);
    f.project();
    // The KSP's true residual is rtol (1e-8) ||rhs||; the ratio is recomputed from the faces.
    // Without the obstacle (cavity, periodic) the pressure is solved by FFT/DCT: round-off.
    EXPECT_LT(f.divergence_ratio(), kind == 1 ? 1.01e-8 : 1e-12) << "kind " << kind;
    if (kind == 1)
      EXPECT_GT(f.poisson_iterations(), 0);
    else
      EXPECT_TRUE(f.spectral_pressure()) << "kind " << kind;
  }
}

TEST(Fluid, ApproximateProjectionRecoversCurlPartSecondOrder) {
  double err[2];
  for (int r = 0; r < 2; ++r) {
    const int n = 32 << r;
    auto grid = make_grid(PETSC_COMM_WORLD, n, true);
    FluidSettings s = cavity(0.0);
    s.kind = fluid::Kind::Periodic;
    FluidSolver f(*grid, s, mask(*grid, none));
    // psi = sin(2 pi x) sin(2 pi y) / (2 pi), phi = cos(2 pi x) cos(4 pi y) / (2 pi)
    const double k = 2 * kPi;
    auto curl = [&](double x, double y, double& u, double& v) {
      u = std::sin(k * x) * std::cos(k * y);
      v = -std::cos(k * x) * std::sin(k * y);
    };
    f.set_velocity([&](double x, double y, double& u, double& v) {
      curl(x, y, u, v);
      u += -std::sin(k * x) * std::cos(2 * k * y);
      v += -2 * std::cos(k * x) * std::sin(2 * k * y);
    });
    f.project();
    const auto u = gather(*grid, f.component(0)), v = gather(*grid, f.component(1));
    double e = 0;
    for (PetscInt j = 0; j < n && !u.empty(); ++j)
      for (PetscInt i = 0; i < n; ++i) {
        double ue, ve;
        curl(grid->centre(0, i), grid->centre(1, j), ue, ve);
        const size_t c = static_cast<size_t>(i + n * j);
        e = std::max({e, std::fabs(u[c] - ue), std::fabs(v[c] - ve)});
      }
    err[r] = max_over_ranks(e);
  }
  const double order = std::log2(err[0] / err[1]);
  EXPECT_LT(err[1], 0.02) << "max error at 64^2";
  EXPECT_GT(order, 1.8) << "errors " << err[0] << ", " << err[1];
}

// The exact FFT/DCT/DST pressure and viscosity solves of a cavity against the KSP ones (forced
// by giving -fluid_ksp_rtol / -fluid_visc_ksp_rtol 1e-13): 20 steps of a 32^2 cavity at
// Re = 100 agree to 1e-9 in both velocity components.
TEST(Fluid, SpectralSolvesAgreeWithKsp) {
  auto grid = make_grid(PETSC_COMM_WORLD, 32, false);
  auto run = [&](bool ksp) {
    if (ksp) {
      PetscOptionsSetValue(nullptr, "-fluid_ksp_rtol", "1e-13");
      PetscOptionsSetValue(nullptr, "-fluid_visc_ksp_rtol", "1e-13");
    }
    auto f = std::make_unique<FluidSolver>(*grid, cavity(0.01), mask(*grid, none));
    for (int s = 0; s < 20; ++s)
      f->step(0.02);
    PetscOptionsClearValue(nullptr, "-fluid_ksp_rtol");
    PetscOptionsClearValue(nullptr, "-fluid_visc_ksp_rtol");
    EXPECT_EQ(f->spectral_pressure(), !ksp);
    EXPECT_EQ(f->spectral_viscosity(), !ksp);
    return f;
  };
  auto sp = run(false), kp = run(true);
  double worst = 0;
  for (int d = 0; d < 2; ++d) {
    const auto a = gather(*grid, sp->component(d)), b = gather(*grid, kp->component(d));
    for (size_t i = 0; i < a.size() && i < b.size(); ++i)
      worst = std::max(worst, std::fabs(a[i] - b[i]));
  }
  worst = max_over_ranks(worst);
  EXPECT_LT(worst, 1e-9);
}

TEST(Fluid, LidDrivenCavityRe100MatchesGhia) {
  // Ghia, Ghia & Shin (1982), Table I, Re = 100: u on the vertical line x = 0.5.
  const double y[17] = {1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000,
                        0.4531, 0.2813, 0.1719, 0.1016, 0.0703, 0.0625, 0.0547, 0.0000};
  const double ug[17] = {1.00000,  0.84123,  0.78871,  0.73722,  0.68717,  0.23151,
                         0.00332,  -0.13641, -0.20581, -0.21090, -0.15662, -0.10150,
                         -0.06434, -0.04775, -0.04192, -0.03717, 0.00000};
  const int n = 64;
  auto grid = make_grid(PETSC_COMM_WORLD, n, false);
  FluidSolver f(*grid, cavity(0.01), mask(*grid, none));
  const double dt = 0.02;
  for (int s = 0; s < 600; ++s)
    f.step(dt);
  const auto u = gather(*grid, f.component(0));
  double worst = 0;
  if (!u.empty()) {
    // Centre-line x = 0.5: mean of columns n/2 - 1 and n/2; linear in y between cell centres,
    // the wall values (0 at y = 0, the lid's 1 at y = 1) beyond the first and last centres.
    std::vector<double> col(static_cast<size_t>(n));
    for (int j = 0; j < n; ++j)
      col[j] =
          0.5 * (u[static_cast<size_t>(n / 2 - 1 + n * j)] + u[static_cast<size_t>(n / 2 + n * j)]);
    for (int q = 0; q < 17; ++q) {
      const double yc = y[q] * n - 0.5; // in cell-centre index units
      double val;
      if (yc < 0)
        val = col[0] * (y[q] * n / 0.5);
      else if (yc > n - 1)
        val = col[n - 1] + (1.0 - col[n - 1]) * (yc - (n - 1)) / 0.5;
      else {
        const int j0 = std::min(static_cast<int>(yc), n - 2);
        val = col[j0] + (yc - j0) * (col[j0 + 1] - col[j0]);
      }
      worst = std::max(worst, std::fabs(val - ug[q]));
      if (comm_size() == 1) printf("y %.4f  u %.5f  ghia %.5f\n", y[q], val, ug[q]);
    }
  }
  worst = max_over_ranks(worst);
  printf("max |u - u_Ghia| = %.4f\n", worst);
  EXPECT_LT(worst, 0.03);
}

TEST(Fluid, ObstacleHasZeroVelocityInside) {
  auto grid = make_grid(PETSC_COMM_WORLD, 48, false);
  FluidSettings s = cavity(0.005);
  s.kind = fluid::Kind::Channel;
  s.inflow = 1.0;
  auto disc = [](double x, double y) { return std::hypot(x - 0.3, y - 0.5) < 0.1; };
  FluidSolver f(*grid, s, mask(*grid, disc));
  for (int k = 0; k < 20; ++k)
    f.step(0.02);
  const auto u = gather(*grid, f.component(0)), v = gather(*grid, f.component(1));
  bool ok = true;
  double flux_out = 0;
  for (PetscInt j = 0; j < 48 && !u.empty(); ++j) {
    for (PetscInt i = 0; i < 48; ++i) {
      const size_t c = static_cast<size_t>(i + 48 * j);
      if (disc(grid->centre(0, i), grid->centre(1, j)) && (u[c] != 0.0 || v[c] != 0.0)) ok = false;
    }
    flux_out += u[static_cast<size_t>(47 + 48 * j)] / 48.0;
  }
  EXPECT_TRUE(all_ranks(ok));
  if (!u.empty()) {
    EXPECT_NEAR(flux_out, 1.0, 0.02) << "outflow flux (inflow 1)";
  }
}

TEST(Fluid, RankCountIndependent) {
  std::vector<double> world[2], self[2];
  for (int pass = 0; pass < 2; ++pass) {
    MPI_Comm comm = pass == 0 ? PETSC_COMM_WORLD : PETSC_COMM_SELF;
    auto grid = make_grid(comm, 40, false);
    auto disc = [](double x, double y) { return std::hypot(x - 0.6, y - 0.4) < 0.12; };
    FluidSolver f(*grid, cavity(0.01), mask(*grid, disc));
    for (int k = 0; k < 20; ++k)
      f.step(0.03);
    for (int d = 0; d < 2; ++d)
      (pass == 0 ? world : self)[d] = gather(*grid, f.component(d));
  }
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  double diff = 0;
  if (rank == 0)
    for (int d = 0; d < 2; ++d)
      for (size_t c = 0; c < self[d].size(); ++c)
        diff = std::max(diff, std::fabs(world[d][c] - self[d][c]));
  diff = max_over_ranks(diff);
  EXPECT_LT(diff, 1e-7);
}
