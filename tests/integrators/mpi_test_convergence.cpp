// Verification of the integrators' order of accuracy, on 1 and 2 ranks.
//
// Manufactured solution (Schnakenberg kinetics, a = 0.1, b = 0.9, gamma = 1, D_u = 0.01,
// D_v = 0.02, unit square or cube): with phi = prod_d sin(k x_d) (k = 2 pi periodic, pi for
// Dirichlet, where phi vanishes on the faces),
//   u_e = 1 + 0.2 phi cos t,   v_e = 0.9 + 0.1 phi sin(t + 1),
// and the sources S = du_e/dt - D lap u_e - R(u_e, v_e) given as -source_u/-source_v.
//  - order in space: error against u_e at time T while refining h (dt ~ h^2 for the explicit
//    scheme, dt ~ h for Strang/Crank-Nicolson): 2 for the 5/7-point Laplacian;
//  - order in time: successive differences on a fixed grid while halving dt: 1 for forward
//    Euler and Lie splitting (backward Euler), 2 for Strang with Crank-Nicolson and trapezoidal
//    reaction and for the TS integrator (ARKIMEX 2E), each in 2-D and 3-D, periodic and
//    Dirichlet;
//  - pure diffusion of a Fourier mode and of a Gaussian against the exact continuous solution
//    (Strang/Crank-Nicolson with zero reaction): order 2.
// Each asserts the least-squares slope of log(error) over >= 3 refinements to within 0.1 of
// the design order. Every table is appended to convergence.csv in the working directory
// (postproc/plot_convergence.py draws it).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

struct Mms {
  int dim = 2;
  bool dirichlet = false;
  std::string phi() const {
    const std::string k = dirichlet ? "pi" : "2*pi";
    std::string s = "(sin(" + k + "*x/Lx)*sin(" + k + "*y/Ly)";
    if (dim == 3) s += "*sin(" + k + "*z/Lz)";
    return s + ")";
  }
  double K2() const { return dim * std::pow(dirichlet ? M_PI : 2 * M_PI, 2); }
  std::string u() const { return "(1 + 0.2*" + phi() + "*cos(t))"; }
  std::string v() const { return "(0.9 + 0.1*" + phi() + "*sin(t+1))"; }
  std::string su() const {
    std::ostringstream o;
    o.precision(17);
    o << "-0.2*" << phi() << "*sin(t) + 0.01*" << K2() << "*0.2*" << phi() << "*cos(t) - (0.1 - "
      << u() << " + " << u() << "^2*" << v() << ")";
    return o.str();
  }
  std::string sv() const {
    std::ostringstream o;
    o.precision(17);
    o << "0.1*" << phi() << "*cos(t+1) + 0.02*" << K2() << "*0.1*" << phi() << "*sin(t+1) - (0.9 - "
      << u() << "^2*" << v() << ")";
    return o.str();
  }
  OptionList options(int n, int steps, double T) const {
    std::string grid = std::to_string(n) + "," + std::to_string(n);
    if (dim == 3) grid += "," + std::to_string(n);
    OptionList o = {{"model", "schnakenberg"},
                    {"grid_n", grid},
                    {"grid_L", "1"},
                    {"grid_bc", dirichlet ? "dirichlet" : "periodic"},
                    {"D_u", "0.01"},
                    {"D_v", "0.02"},
                    {"init_u", replace_t(u(), "0")},
                    {"init_v", replace_t(v(), "0")},
                    {"source_u", su()},
                    {"source_v", sv()},
                    {"dt", fmt(T / steps)},
                    {"clamp", "false"}};
    if (dirichlet) {
      o.push_back({"dirichlet_u", "1"});
      o.push_back({"dirichlet_v", "0.9"});
    }
    return o;
  }
  static std::string replace_t(std::string s, const std::string& by) {
    for (size_t p = 0; (p = s.find("(t", p)) != std::string::npos;) {
      if (s.compare(p, 3, "(t)") == 0)
        s.replace(p + 1, 1, by);
      else if (s.compare(p, 4, "(t+1") == 0)
        s.replace(p + 1, 1, by);
      ++p;
    }
    return s;
  }
  static std::string fmt(double v) {
    std::ostringstream o;
    o.precision(17);
    o << v;
    return o.str();
  }
};

OptionList with(OptionList o, const OptionList& extra) {
  for (const auto& e : extra)
    o.push_back(e);
  return o;
}

// Max-norm error of species s against an expression of (x, y, z, t) at the run's final time.
double error_vs(Simulation& sim, int s, const std::string& exact) {
  ValueSpec e("exact", exact, sim.grid().spec(), 1);
  const Grid& g = sim.grid();
  const Box& ob = g.owned();
  const PetscScalar* a;
  VecGetArrayRead(sim.state()[s], &a);
  double err = 0;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        err = std::max(err, std::abs(a[g.local_index(i, j, k)] - e.at_cell(i, j, k, sim.time())));
  VecRestoreArrayRead(sim.state()[s], &a);
  return max_over_ranks(err);
}

// `steps` steps in passes of Simulation::fuse_steps() (1 unless the run fuses steps).
std::unique_ptr<Simulation> run(const OptionList& opts, int steps) {
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  for (int n = 0; n < steps;) {
    const int pass = static_cast<int>(std::min<PetscInt>(sim->fuse_steps(), steps - n));
    sim->advance(pass);
    n += pass;
  }
  return sim;
}

// Least-squares slope of log(err) against log(x).
double slope(const std::vector<double>& x, const std::vector<double>& err) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(err[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void record(const std::string& name, const std::string& kind, const std::vector<double>& x,
            const std::vector<double>& err, double order) {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank != 0) return;
  std::ofstream f("convergence.csv", std::ios::app);
  for (size_t i = 0; i < x.size(); ++i)
    f << name << "," << kind << "," << comm_size() << "," << x[i] << "," << err[i] << "," << order
      << "\n";
  std::printf("%-40s %s order %.3f:", name.c_str(), kind.c_str(), order);
  for (size_t i = 0; i < x.size(); ++i)
    std::printf(" (%.4g, %.3e)", x[i], err[i]);
  std::printf("\n");
}

// Space refinement: n = n0 * 2^m, steps = steps0 * (2^m)^p (p = 2: dt ~ h^2, p = 1: dt ~ h).
double space_order(const std::string& name, const Mms& mms, const OptionList& scheme, int n0,
                   int steps0, int p, double T) {
  std::vector<double> h, err;
  for (int m = 0; m < 4; ++m) {
    const int n = n0 << m, steps = steps0 * (1 << (p * m));
    auto sim = run(with(mms.options(n, steps, T), scheme), steps);
    h.push_back(1.0 / n);
    err.push_back(error_vs(*sim, 0, mms.u()));
  }
  const double order = slope(h, err);
  record(name, "space", h, err, order);
  return order;
}

// Time refinement on a fixed grid: successive differences of u (gathered on rank 0).
double time_order(const std::string& name, const Mms& mms, const OptionList& scheme, int n,
                  int steps0, double T) {
  std::vector<std::vector<double>> u;
  std::vector<double> dt, diff;
  for (int m = 0; m < 5; ++m) {
    const int steps = steps0 << m;
    auto sim = run(with(mms.options(n, steps, T), scheme), steps);
    u.push_back(gather_all(sim->grid(), sim->state()[0]));
    dt.push_back(T / steps);
  }
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  for (int m = 0; m + 1 < 5; ++m) {
    double d = 0;
    if (rank == 0)
      for (size_t c = 0; c < u[m].size(); ++c)
        d = std::max(d, std::abs(u[m][c] - u[m + 1][c]));
    MPI_Bcast(&d, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
    diff.push_back(d);
  }
  dt.pop_back();
  const double order = slope(dt, diff);
  record(name, "time", dt, diff, order);
  return order;
}

const OptionList kExplicit = {{"integrator", "explicit"}};
// The split cases solve the diffusion substeps by KSP to 1e-12 (the default tolerance, 1e-8, is
// set for the splitting error at practical step sizes, not for differences at tiny dt).
const OptionList kLie = {
    {"integrator", "split"}, {"split_ordering", "lie"}, {"diffusion_ksp_rtol", "1e-12"}};
const OptionList kStrang = {
    {"integrator", "split"}, {"split_ordering", "strang"}, {"diffusion_ksp_rtol", "1e-12"}};
// Strang with the reaction half-steps of consecutive steps merged (the whole run one pass).
const OptionList kStrangFused = {{"integrator", "split"},
                                 {"split_ordering", "strang"},
                                 {"diffusion_ksp_rtol", "1e-12"},
                                 {"split_fuse_reaction", "true"}};
// Strang with the explicit classical Runge-Kutta reaction substep.
const OptionList kStrangRk4 = {{"integrator", "split"},
                               {"split_ordering", "strang"},
                               {"diffusion_ksp_rtol", "1e-12"},
                               {"split_reaction", "rk4"}};

} // namespace

TEST(ConvergenceSpace, Explicit2DPeriodic) {
  EXPECT_NEAR(space_order("explicit 2d periodic", {2, false}, kExplicit, 8, 4, 2, 0.1), 2.0, 0.1);
}
TEST(ConvergenceSpace, Explicit2DDirichlet) {
  EXPECT_NEAR(space_order("explicit 2d dirichlet", {2, true}, kExplicit, 8, 2, 2, 0.1), 2.0, 0.1);
}
TEST(ConvergenceSpace, Explicit3DPeriodic) {
  EXPECT_NEAR(space_order("explicit 3d periodic", {3, false}, kExplicit, 6, 2, 2, 0.05), 2.0, 0.1);
}
TEST(ConvergenceSpace, Strang2DPeriodic) {
  EXPECT_NEAR(space_order("strang-cn 2d periodic", {2, false}, kStrang, 8, 2, 1, 0.2), 2.0, 0.1);
}
TEST(ConvergenceSpace, Strang3DDirichlet) {
  EXPECT_NEAR(space_order("strang-cn 3d dirichlet", {3, true}, kStrang, 6, 2, 1, 0.2), 2.0, 0.1);
}

// Order in time of every scheme on every geometry: {explicit, Lie, Strang, TS ARKIMEX 2E, Strang
// fused, Strang with the RK4 reaction} x
// {2-D, 3-D} x {periodic, Dirichlet}.
struct TimeCase {
  const char* name;
  OptionList scheme;
  int steps0;
  double order;
};

const TimeCase kTimeCases[] = {
    {"explicit", kExplicit, 32, 1.0},
    {"lie-be", kLie, 64, 1.0},
    {"strang-cn", kStrang, 4, 2.0},
    {"ts-arkimex2e", {{"integrator", "ts"}}, 4, 2.0},
    {"strang-cn-fused", kStrangFused, 4, 2.0},
    {"strang-cn-rk4", kStrangRk4, 4, 2.0},
};

class ConvergenceTime
    : public ::testing::TestWithParam<std::tuple<int /*case*/, int /*dim*/, bool /*dirichlet*/>> {};

TEST_P(ConvergenceTime, DesignOrder) {
  const auto [c, dim, dirichlet] = GetParam();
  const TimeCase& tc = kTimeCases[c];
  const std::string name = std::string(tc.name) + " " + std::to_string(dim) + "d " +
                           (dirichlet ? "dirichlet" : "periodic");
  EXPECT_NEAR(time_order(name, {dim, dirichlet}, tc.scheme, dim == 2 ? 16 : 8, tc.steps0, 0.4),
              tc.order, 0.1);
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, ConvergenceTime,
                         ::testing::Combine(::testing::Range(0, 6), ::testing::Values(2, 3),
                                            ::testing::Bool()));

TEST(ConvergenceSpace, TsArkimex2DDirichlet) {
  EXPECT_NEAR(
      space_order("ts-arkimex2e 2d dirichlet", {2, true}, {{"integrator", "ts"}}, 8, 2, 1, 0.2),
      2.0, 0.1);
}
TEST(ConvergenceSpace, Strang2DDirichlet) {
  EXPECT_NEAR(space_order("strang-cn 2d dirichlet", {2, true}, kStrang, 8, 2, 1, 0.2), 2.0, 0.1);
}

TEST(PureDiffusion, FourierModeCrankNicolson) {
  // u = 1 + sin(2 pi x) sin(2 pi y) exp(-8 pi^2 D t), D = 0.01; dt ~ h.
  std::vector<double> h, err;
  const double T = 0.5;
  for (int m = 0; m < 4; ++m) {
    const int n = 8 << m, steps = 2 << m;
    auto sim = run({{"grid_n", std::to_string(n) + "," + std::to_string(n)},
                    {"grid_L", "1"},
                    {"params_s", "0"},
                    {"clamp", "false"},
                    {"D_a", "0.01"},
                    {"D_b", "0"},
                    {"init_a", "1 + sin(2*pi*x)*sin(2*pi*y)"},
                    {"integrator", "split"},
                    {"dt", Mms::fmt(T / steps)}},
                   steps);
    h.push_back(1.0 / n);
    err.push_back(error_vs(*sim, 0, "1 + sin(2*pi*x)*sin(2*pi*y)*exp(-8*pi^2*0.01*t)"));
  }
  const double order = slope(h, err);
  record("diffusion fourier strang-cn", "space+time", h, err, order);
  EXPECT_NEAR(order, 2.0, 0.1);
}

TEST(PureDiffusion, GaussianCrankNicolson) {
  // 2-D heat kernel: s2(t) = s0^2 + 2 D t, u = (s0^2 / s2) exp(-r^2 / (2 s2)), s0 = 0.05,
  // D = 0.002 (narrow enough that the periodic images stay below 1e-12).
  std::vector<double> h, err;
  const double T = 0.5;
  for (int m = 0; m < 4; ++m) {
    const int n = 32 << m, steps = 2 << m;
    auto sim = run({{"grid_n", std::to_string(n) + "," + std::to_string(n)},
                    {"grid_L", "1"},
                    {"params_s", "0"},
                    {"clamp", "false"},
                    {"D_a", "0.002"},
                    {"D_b", "0"},
                    {"init_a", "exp(-r^2/(2*0.0025))"},
                    {"integrator", "split"},
                    {"dt", Mms::fmt(T / steps)}},
                   steps);
    h.push_back(1.0 / n);
    err.push_back(
        error_vs(*sim, 0, "(0.0025/(0.0025 + 0.004*t))*exp(-r^2/(2*(0.0025 + 0.004*t)))"));
  }
  const double order = slope(h, err);
  record("diffusion gaussian strang-cn", "space+time", h, err, order);
  EXPECT_NEAR(order, 2.0, 0.1);
}

// Fused Strang really merges the half-steps (one pass of the whole run; a different rounding
// of the same second-order scheme), and stays as accurate as unfused Strang.
TEST(SplitFusion, MergesHalfStepsAtTheSameAccuracy) {
  const Mms mms{2, false};
  const int n = 16, steps = 8;
  auto plain = run(with(mms.options(n, steps, 0.4), kStrang), steps);
  auto fused = run(with(mms.options(n, steps, 0.4), kStrangFused), steps);
  EXPECT_EQ(plain->fuse_steps(), 1);
  EXPECT_GT(fused->fuse_steps(), steps);
  const auto a = gather_all(plain->grid(), plain->state()[0]);
  const auto b = gather_all(fused->grid(), fused->state()[0]);
  double d = 0;
  for (size_t c = 0; c < a.size(); ++c)
    d = std::max(d, std::abs(a[c] - b[c]));
  MPI_Bcast(&d, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  EXPECT_GT(d, 1e-12);
  const double ea = error_vs(*plain, 0, mms.u()), eb = error_vs(*fused, 0, mms.u());
  EXPECT_LT(eb, 2 * ea) << "fused " << eb << " unfused " << ea;
  EXPECT_LT(d, ea) << "fused and unfused Strang differ by more than their error";
}

// Where the diffusion is a tridiagonal solve in place, a reaction substep followed by a
// diffusion substep runs plane by plane inside the latter's first pass
// (SplitSettings::fuse_planes): the same arithmetic as a reaction pass before the diffusion, so
// bitwise the same states (2-D and 3-D, plain and fused Strang, with the time-dependent sources
// of the manufactured solution).
TEST(SplitFusion, ReactionInsideTheDiffusionPassIsBitwiseTheSame) {
  for (int dim : {2, 3})
    for (const char* fuse : {"false", "true"}) {
      const Mms mms{dim, false};
      const int n = 8, steps = 6;
      // Long along the slowest axis, so that PETSc splits the ranks in slabs of it (the in-place
      // tridiagonal solve needs them).
      const OptionList opts = {{"grid_n", dim == 2 ? "10,32" : "8,6,24"},
                               {"integrator", "split"},
                               {"split_fuse_reaction", fuse},
                               {"diffusion_solver", "spectral"},
                               {"diffusion_slow_axis", "tridiagonal"}};
      auto in_pass = run(with(mms.options(n, steps, 0.4), opts), steps);
      auto apart = run(
          with(with(mms.options(n, steps, 0.4), opts), {{"split_fuse_planes", "false"}}), steps);
      const std::string what = std::to_string(dim) + "-D, fused " + fuse;
      EXPECT_EQ(in_pass->split_integrator()->planes_fused_substeps(), steps) << what;
      EXPECT_EQ(apart->split_integrator()->planes_fused_substeps(), 0) << what;
      for (int s = 0; s < 2; ++s) {
        const auto a = gather_all(in_pass->grid(), in_pass->state()[s]);
        const auto b = gather_all(apart->grid(), apart->state()[s]);
        int same = a == b ? 1 : 0;
        MPI_Bcast(&same, 1, MPI_INT, 0, PETSC_COMM_WORLD);
        EXPECT_EQ(same, 1) << what << ", species " << s;
      }
    }
}
