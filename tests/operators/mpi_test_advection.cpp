// Semi-Lagrangian advection (operators/advection_stage.hpp) through the Simulation, with a
// custom model whose rate is 0 and D = 0, so the run is pure transport dA/dt = -(u . grad) A:
// (1) constant velocity on a periodic square against the exactly shifted profile: convergence
//     order of the linear scheme at a fixed Courant number (dt ~ h: error ~ h^2/dt, order 1)
//     and at a fixed dt (error ~ h^2/dt with dt fixed, order 2), and of the cubic scheme
//     (order 3 at a fixed Courant number); mass drift (exactly conserved up to round-off for a
//     uniform shift of a periodic field, linear scheme);
// (2) solid-body rotation about the centre of a zero-flux (clamped) square against the
//     exactly rotated profile, in the disk whose trajectories stay inside the domain; orders
//     of both schemes (rk2 back-trace); mass drift reported;
// (3) a velocity using t (uniform, u_x = 1 + t): the midpoint velocity makes the displacement
//     exact for a linear t, so the error equals the steady case's;
// (4) every integrator (explicit, split, ts) applies the stage after its step;
// (5) 1 vs 2 vs 4 ranks bitwise identical (explicit integrator): the run on PETSC_COMM_WORLD
//     against the same run on PETSC_COMM_SELF (on every rank), with Courant numbers above a
//     rank's extent (back-traces crossing several ranks), a velocity using t, periodic, clamped
//     and Dirichlet axes, linear and cubic, rk2 and euler back-traces, 2-D and 3-D.
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "core/options.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

const double kPi = 3.14159265358979323846;

OptionList transport_run(int n, double L, const std::string& bc, double dt, int steps) {
  return {{"model", "custom"},
          {"species", "a"},
          {"rate_a", "0"},
          {"D_a", "0"},
          {"grid_n", std::to_string(n) + "," + std::to_string(n)},
          {"grid_L", format_double(L)},
          {"grid_bc", bc},
          {"dt", format_double(dt)},
          {"steps", std::to_string(steps)},
          {"summary", "false"}};
}

struct Errors {
  double l2 = 0, max = 0, mass_drift = 0;
};

using Profile = std::function<double(double x, double y)>;

// Run `steps` steps; compare with exact(x, y) at cells where mask(x, y) (RMS and max error), and
// the relative change of sum(a) over the whole grid.
Errors run_and_compare(OptionList opts, int steps, const Profile& exact,
                       const std::function<bool(double, double)>& mask) {
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  const auto a0 = gather_all(sim->grid(), sim->state()[0]);
  for (int s = 0; s < steps; ++s)
    sim->step();
  const auto a = gather_all(sim->grid(), sim->state()[0]);
  Errors e;
  const GridSpec& g = sim->grid().spec();
  if (!a.empty()) {
    double sum = 0, cnt = 0, m0 = 0, m1 = 0;
    for (PetscInt j = 0; j < g.n[1]; ++j)
      for (PetscInt i = 0; i < g.n[0]; ++i) {
        const size_t c = static_cast<size_t>(i + g.n[0] * j);
        m0 += a0[c];
        m1 += a[c];
        const double x = sim->grid().centre(0, i), y = sim->grid().centre(1, j);
        if (!mask(x, y)) continue;
        const double d = a[c] - exact(x, y);
        sum += d * d;
        cnt += 1;
        e.max = std::max(e.max, std::abs(d));
      }
    e.l2 = std::sqrt(sum / cnt);
    e.mass_drift = (m1 - m0) / m0;
  }
  MPI_Bcast(&e, 3, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  return e;
}

// Periodic profile on the unit square, shifted by (sx, sy).
double bump(double x, double y) {
  return std::exp(std::sin(2 * kPi * x) + 0.5 * std::cos(2 * kPi * y));
}

// Constant velocity (1, 2) over T = 0.5 on n^2 cells.
Errors constant_velocity(int n, double dt, const std::string& scheme) {
  const double T = 0.5;
  const int steps = static_cast<int>(std::lround(T / dt));
  auto opts = transport_run(n, 1.0, "periodic", dt, steps);
  opts.insert(opts.end(), {{"init_a", "exp(sin(2*_pi*x) + 0.5*cos(2*_pi*y))"},
                           {"advect", "a"},
                           {"advection_scheme", scheme},
                           {"velocity_x", "1"},
                           {"velocity_y", "2"}});
  const double t = steps * dt;
  return run_and_compare(
      opts, steps, [&](double x, double y) { return bump(x - t, y - 2 * t); },
      [](double, double) { return true; });
}

double order(const Errors& coarse, const Errors& fine) {
  return std::log2(coarse.l2 / fine.l2);
}

void report(const char* what, int n, const Errors& e) {
  PetscPrintf(PETSC_COMM_WORLD, "  %-44s n %4d  L2 %.3e  max %.3e  mass drift %+.2e\n", what, n,
              e.l2, e.max, e.mass_drift);
}

} // namespace

TEST(Advection, ConstantVelocityOrders) {
  // The linear scheme's error is a numerical diffusion phi (1 - phi) h^2 / (2 dt) per axis, phi
  // the fractional part of the axis' Courant number. Fixed Courant numbers 1/3 along x, 2/3
  // along y (dt = h/3): order 1. Fixed dt = 1/192: Courant numbers (1/3, 2/3) at n = 64 and
  // (2/3, 4/3) at n = 128, the same phi (1 - phi) = 2/9 on both axes, so order 2 from 64 to 128.
  std::vector<Errors> lin, cub, fixed;
  for (int n : {32, 64, 128}) {
    lin.push_back(constant_velocity(n, 1.0 / (3 * n), "linear"));
    report("linear, Courant (1/3, 2/3) (dt = h/3)", n, lin.back());
    cub.push_back(constant_velocity(n, 1.0 / (3 * n), "cubic"));
    report("cubic, Courant (1/3, 2/3) (dt = h/3)", n, cub.back());
    fixed.push_back(constant_velocity(n, 1.0 / 192, "linear"));
    report("linear, fixed dt 1/192", n, fixed.back());
  }
  const double ol = order(lin[1], lin[2]), oc = order(cub[1], cub[2]),
               of = order(fixed[1], fixed[2]);
  PetscPrintf(PETSC_COMM_WORLD,
              "  orders (64 -> 128): linear fixed Courant %.3f, cubic fixed Courant %.3f, linear "
              "fixed dt %.3f\n",
              ol, oc, of);
  EXPECT_NEAR(ol, 1.0, 0.2);
  EXPECT_NEAR(oc, 3.0, 0.35);
  EXPECT_NEAR(of, 2.0, 0.3);
  // A uniform shift of a periodic field: the linear scheme's weights sum to 1 over the sources.
  for (const auto& e : lin)
    EXPECT_LT(std::abs(e.mass_drift), 1e-13);
}

namespace {

// Solid-body rotation, angular speed 2 pi, about (1, 1) on [0, 2]^2 (zero-flux walls: back-traces
// leaving the domain clamp), over a quarter turn; a Gaussian at (1, 1.4).
Errors rotation(int n, double courant, const std::string& scheme, const std::string& backtrace) {
  const double L = 2, w = 2 * kPi, T = 0.25, h = L / n;
  // Courant number at the domain's edge midpoints (|u| = w at distance 1).
  int steps = static_cast<int>(std::ceil(T / (courant * h / w)));
  const double dt = T / steps;
  auto opts = transport_run(n, L, "neumann", dt, steps);
  opts.insert(opts.end(), {{"init_a", "exp(-((x-1)^2 + (y-1.4)^2)/(2*0.15^2))"},
                           {"advect", "a"},
                           {"advection_scheme", scheme},
                           {"advection_backtrace", backtrace},
                           {"velocity_x", "-2*_pi*(y-1)"},
                           {"velocity_y", "2*_pi*(x-1)"}});
  const double t = steps * dt;
  return run_and_compare(
      opts, steps,
      [&](double x, double y) {
        const double c = std::cos(w * t), s = std::sin(w * t);
        const double x0 = 1 + c * (x - 1) + s * (y - 1), y0 = 1 - s * (x - 1) + c * (y - 1);
        return std::exp(-((x0 - 1) * (x0 - 1) + (y0 - 1.4) * (y0 - 1.4)) / (2 * 0.15 * 0.15));
      },
      [](double x, double y) { return (x - 1) * (x - 1) + (y - 1) * (y - 1) < 0.9 * 0.9; });
}

} // namespace

TEST(Advection, RotationOrders) {
  std::vector<Errors> lin, cub, eul;
  for (int n : {48, 96, 192}) {
    lin.push_back(rotation(n, 0.5, "linear", "rk2"));
    report("rotation, linear rk2, Courant 0.5", n, lin.back());
    cub.push_back(rotation(n, 0.5, "cubic", "rk2"));
    report("rotation, cubic rk2, Courant 0.5", n, cub.back());
    eul.push_back(rotation(n, 0.5, "cubic", "euler"));
    report("rotation, cubic euler (eq. 20), Courant 0.5", n, eul.back());
  }
  const double ol = order(lin[1], lin[2]), oc = order(cub[1], cub[2]), oe = order(eul[1], eul[2]);
  PetscPrintf(PETSC_COMM_WORLD,
              "  orders (96 -> 192): linear rk2 %.3f, cubic rk2 %.3f, cubic euler %.3f\n", ol, oc,
              oe);
  EXPECT_NEAR(ol, 1.0, 0.25);
  EXPECT_GT(oc, 1.8);
  EXPECT_NEAR(oe, 1.0, 0.3);
  EXPECT_LT(cub[2].l2, lin[2].l2 / 5);
}

TEST(Advection, TimeDependentVelocityMidpoint) {
  // u_x = 1 + t: displacement t + t^2/2, exact with the velocity at each step's midpoint; the
  // velocity at each step's start would displace by T dt / 2 too little (7.8e-4, an error of
  // ~0.02 in this profile), so the bound below (the cubic scheme's interpolation error at this
  // resolution, cf. ConstantVelocityOrders) tells the two apart.
  const int n = 128;
  const double dt = 0.4 / n, T = 0.5;
  const int steps = static_cast<int>(std::lround(T / dt));
  auto opts = transport_run(n, 1.0, "periodic", dt, steps);
  opts.insert(opts.end(), {{"init_a", "exp(sin(2*_pi*x) + 0.5*cos(2*_pi*y))"},
                           {"advect", "a"},
                           {"advection_scheme", "cubic"},
                           {"velocity_x", "1 + t"},
                           {"velocity_y", "0"}});
  const double t = steps * dt;
  const Errors e = run_and_compare(
      opts, steps, [&](double x, double y) { return bump(x - t - 0.5 * t * t, y); },
      [](double, double) { return true; });
  report("u_x = 1 + t, cubic, Courant 0.4-0.6", n, e);
  EXPECT_LT(e.max, 1e-3);
}

TEST(Advection, EveryIntegratorAdvects) {
  // With D = 0 and a zero rate every integrator's step leaves the state alone: the stage
  // after it gives the same transport (the cubic scheme's error at n = 64, ConstantVelocityOrders).
  std::vector<double> l2;
  for (const char* integ : {"explicit", "split", "ts"}) {
    const int n = 64;
    const double dt = 1.0 / (3 * n);
    const int steps = 40;
    auto opts = transport_run(n, 1.0, "periodic", dt, steps);
    opts.insert(opts.end(), {{"init_a", "exp(sin(2*_pi*x) + 0.5*cos(2*_pi*y))"},
                             {"advect", "a"},
                             {"advection_scheme", "cubic"},
                             {"velocity_x", "1"},
                             {"velocity_y", "2"},
                             {"integrator", integ}});
    const double t = steps * dt;
    const Errors e = run_and_compare(
        opts, steps, [&](double x, double y) { return bump(x - t, y - 2 * t); },
        [](double, double) { return true; });
    report(integ, n, e);
    EXPECT_LT(e.max, 3e-3) << integ;
    l2.push_back(e.l2);
  }
  EXPECT_NEAR(l2[1], l2[0], 1e-12 * l2[0]);
  EXPECT_NEAR(l2[2], l2[0], 1e-12 * l2[0]);
}

namespace {

// The final state of `opts` on comm, gathered on its rank 0.
std::vector<double> final_state(MPI_Comm comm, const OptionList& opts, int steps) {
  set_options(opts);
  Options opt(comm);
  Simulation sim(comm, opt, "");
  for (int s = 0; s < steps; ++s)
    sim.step();
  std::vector<double> all;
  for (size_t q = 0; q < sim.state().size(); ++q) {
    const auto a = gather_all(sim.grid(), sim.state()[q]);
    all.insert(all.end(), a.begin(), a.end());
  }
  return all;
}

// World run against the same run on PETSC_COMM_SELF: bitwise equal on rank 0.
void expect_rank_independent(const OptionList& opts, int steps, const char* what) {
  const auto world = final_state(PETSC_COMM_WORLD, opts, steps);
  const auto self = final_state(PETSC_COMM_SELF, opts, steps);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  bool same = true, sane = true;
  if (rank == 0) {
    same = world.size() == self.size() &&
           std::memcmp(world.data(), self.data(), world.size() * sizeof(double)) == 0;
    // Not vacuous: finite values that vary.
    const auto [lo, hi] = std::minmax_element(world.begin(), world.end());
    sane = std::all_of(world.begin(), world.end(), [](double v) { return std::isfinite(v); }) &&
           *hi - *lo > 1e-3;
  }
  EXPECT_TRUE(all_ranks(sane)) << what;
  PetscPrintf(PETSC_COMM_WORLD, "  %s: %d rank(s) vs 1 rank %s\n", what, comm_size(),
              same ? "bitwise identical" : "DIFFERENT");
  EXPECT_TRUE(all_ranks(same)) << what;
}

} // namespace

TEST(Advection, RanksBitwiseIdentical) {
  // 24 x 20 cells: 12 x 10 per rank on 4 ranks; Courant numbers up to ~15 cross several ranks.
  const OptionList base = {{"model", "gray_scott"},
                           {"grid_n", "24,20"},
                           {"grid_bc", "periodic,neumann"},
                           {"init_a", "1 - 0.5*disk(8, 10, 4) +- 10%"},
                           {"init_b", "0.25*disk(8, 10, 4) +- 10%"},
                           {"dt", "1"},
                           {"advect", "a,b"},
                           {"velocity_x", "3*cos(0.3*y) + 12"},
                           {"velocity_y", "2*sin(0.25*x + t)"},
                           {"summary", "false"}};
  // The explicit integrator (itself bitwise rank-independent); the split and TS integrators'
  // Krylov solves are not (block Jacobi in parallel), whatever the advection does.
  for (const char* scheme : {"linear", "cubic"})
    for (const char* backtrace : {"rk2", "euler"}) {
      OptionList o = base;
      o.insert(o.end(), {{"advection_scheme", scheme}, {"advection_backtrace", backtrace}});
      expect_rank_independent(o, 12, (std::string(scheme) + ", " + backtrace).c_str());
    }
  const OptionList three_d = {{"model", "custom"},       {"species", "a"},
                              {"rate_a", "0.1*a*(1-a)"}, {"D_a", "0.05"},
                              {"grid_n", "12,10,8"},     {"grid_bc", "neumann,periodic,dirichlet"},
                              {"init_a", "0.5 +- 40%"},  {"dt", "0.5"},
                              {"advect", "a"},           {"advection_scheme", "cubic"},
                              {"velocity_x", "-(y-5)"},  {"velocity_y", "(x-6)"},
                              {"velocity_z", "4 + z"},   {"summary", "false"}};
  expect_rank_independent(three_d, 8, "3-D cubic, neumann/periodic/dirichlet");
  OptionList tri = three_d;
  for (auto& [k, v] : tri)
    if (k == "advection_scheme") v = "linear";
  expect_rank_independent(tri, 8, "3-D trilinear");
}
