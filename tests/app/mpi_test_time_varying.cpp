// Time-dependent diffusion coefficients and Dirichlet values through the Simulation, with every
// integrator, against closed forms (reaction switched off: Gray-Scott with F = k = s = 0 and
// a = 0, so b only diffuses):
// (1) D(t) = D0 (1 + 0.5 sin(3 t)) on a periodic grid from b = sin(2 pi x): the discrete
//     Fourier mode decays exactly as b = sin(2 pi x) exp(-lambda_h int_0^T D dt) in time, with
//     the 5-point eigenvalue lambda_h = (4 / h^2) sin^2(pi h); explicit Euler (D at the step's
//     start) converges with order 1, split (Strang, Crank-Nicolson, D at the substep's
//     midpoint) and TS (ARKIMEX 2E, D at the stage times) with order 2. The same D written as
//     a field (a term in x that is 0) gives the same numbers.
// (2) Dirichlet values g(t) on the x faces: b = 0.5 sin(2 t) + (1 + t^2) x with the source
//     S = cos(2 t) + 2 t x is linear in x at every t, which the cell-centred Dirichlet scheme
//     represents exactly: only the time error remains (order 1 explicit, 2 split and TS), and
//     boundary values frozen at t = 0 would leave an O(1) error.
// (3) A constant-in-time D is untouched by the mechanism (no time-dependent term is made).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "core/user_error.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

constexpr double kD0 = 0.01, kT = 2.0;
constexpr int kNx = 32;

OptionList no_reaction() {
  return {{"model", "gray_scott"}, {"params_F", "0"}, {"params_k", "0"},
          {"params_s", "0"},       {"init_a", "0"},   {"summary", "false"}};
}

// Max error of b at T against `exact(x, T)` after T / dt steps.
template <class Exact> double run_error(OptionList opts, double T, double dt, const Exact& exact) {
  opts.push_back({"dt", std::to_string(dt)});
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int n = 0; n < steps; ++n)
    sim->step();
  const auto b = gather_all(sim->grid(), sim->state()[1]);
  const GridSpec& g = sim->grid().spec();
  double err = 0;
  for (size_t c = 0; c < b.size(); ++c) {
    const double x = (static_cast<double>(c % static_cast<size_t>(g.n[0])) + 0.5) * g.h(0);
    err = std::max(err, std::abs(b[c] - exact(x, T)));
  }
  MPI_Bcast(&err, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  return err;
}

double mode_error(const OptionList& integrator, double dt, const std::string& D) {
  OptionList opts = no_reaction();
  opts.insert(opts.end(), {{"grid_n", std::to_string(kNx) + ",4"},
                           {"grid_L", "1"},
                           {"init_b", "sin(2*pi*x)"},
                           {"D_b", D}});
  opts.insert(opts.end(), integrator.begin(), integrator.end());
  const double h = 1.0 / kNx, s = std::sin(M_PI * h);
  const double lambda = 4.0 / (h * h) * s * s;
  auto exact = [lambda](double x, double T) {
    const double intD = kD0 * (T + 0.5 * (1 - std::cos(3 * T)) / 3.0);
    return std::sin(2 * M_PI * x) * std::exp(-lambda * intD);
  };
  return run_error(opts, kT, dt, exact);
}

const std::string kDt = "0.01*(1 + 0.5*sin(3*t))";

double mode_order(const OptionList& integrator, double dt, const char* label, double* fine) {
  const double e1 = mode_error(integrator, dt, kDt), e2 = mode_error(integrator, dt / 2, kDt);
  const double order = std::log2(e1 / e2);
  PetscPrintf(PETSC_COMM_WORLD, "  D(t) %s: error %.3e (dt %g), %.3e (dt %g), order %.3f\n", label,
              e1, dt, e2, dt / 2, order);
  *fine = e2;
  return order;
}

} // namespace

TEST(TimeVarying, DiffusionFourierModeClosedForm) {
  double fine = 0;
  EXPECT_NEAR(mode_order({{"integrator", "explicit"}}, 0.02, "explicit", &fine), 1.0, 0.15);
  EXPECT_LT(fine, 2e-3);
  const OptionList split = {{"integrator", "split"}, {"diffusion_ksp_rtol", "1e-13"}};
  EXPECT_NEAR(mode_order(split, 0.2, "split (strang)", &fine), 2.0, 0.2);
  EXPECT_LT(fine, 1e-3);
  const OptionList ts = {{"integrator", "ts"}, {"ksp_rtol", "1e-13"}};
  EXPECT_NEAR(mode_order(ts, 0.2, "ts (arkimex 2e)", &fine), 2.0, 0.2);
  EXPECT_LT(fine, 1e-3);
  // A D that varies in x by a zero term takes the field path: the same numbers.
  const double uniform = mode_error(split, 0.1, kDt);
  const double field = mode_error(split, 0.1, kDt + " + 0*x");
  PetscPrintf(PETSC_COMM_WORLD, "  D(x, t) as a field (split, dt 0.1): %.3e vs %.3e\n", field,
              uniform);
  EXPECT_NEAR(field, uniform, 1e-12);
}

TEST(TimeVarying, ExplicitTsDiffusionFollowsStageTimes) {
  // -ts_diffusion explicit with classical RK4: the diffusion term in the right-hand side at
  // the stage times (fourth order in time; here limited by the tolerance only).
  const OptionList rk4 = {
      {"integrator", "ts"}, {"ts_diffusion", "explicit"}, {"ts_type", "rk"}, {"ts_rk_type", "4"}};
  const double e = mode_error(rk4, 0.02, kDt);
  PetscPrintf(PETSC_COMM_WORLD, "  D(t) ts rk4 (explicit diffusion), dt 0.02: error %.3e\n", e);
  EXPECT_LT(e, 1e-7);
}

namespace {

double dirichlet_error(const OptionList& integrator, double dt) {
  OptionList opts = no_reaction();
  opts.insert(opts.end(), {{"grid_n", "16,4"},
                           {"grid_L", "1"},
                           {"grid_bc", "dirichlet,periodic"},
                           {"D_b", "0.05"},
                           {"init_b", "x"},
                           {"dirichlet_b", "0.5*sin(2*t) + (1 + t*t)*x"},
                           {"source_b", "cos(2*t) + 2*t*x"}});
  opts.insert(opts.end(), integrator.begin(), integrator.end());
  auto exact = [](double x, double T) { return 0.5 * std::sin(2 * T) + (1 + T * T) * x; };
  return run_error(opts, 1.0, dt, exact);
}

double dirichlet_order(const OptionList& integrator, double dt, const char* label, double* fine) {
  const double e1 = dirichlet_error(integrator, dt), e2 = dirichlet_error(integrator, dt / 2);
  const double order = std::log2(e1 / e2);
  PetscPrintf(PETSC_COMM_WORLD, "  g(t) %s: error %.3e (dt %g), %.3e (dt %g), order %.3f\n", label,
              e1, dt, e2, dt / 2, order);
  *fine = e2;
  return order;
}

} // namespace

TEST(TimeVarying, DirichletValuesClosedForm) {
  double fine = 0;
  EXPECT_NEAR(dirichlet_order({{"integrator", "explicit"}}, 0.02, "explicit", &fine), 1.0, 0.2);
  EXPECT_LT(fine, 5e-3);
  const OptionList split = {{"integrator", "split"}, {"diffusion_ksp_rtol", "1e-13"}};
  EXPECT_NEAR(dirichlet_order(split, 0.1, "split (strang)", &fine), 2.0, 0.25);
  EXPECT_LT(fine, 1e-3);
  const OptionList ts = {{"integrator", "ts"}, {"ksp_rtol", "1e-13"}};
  EXPECT_NEAR(dirichlet_order(ts, 0.1, "ts (arkimex 2e)", &fine), 2.0, 0.25);
  EXPECT_LT(fine, 1e-3);
}

TEST(TimeVarying, ConstantInTimeMakesNoTimedTerm) {
  OptionList opts = no_reaction();
  opts.insert(opts.end(), {{"grid_n", "16,8"}, {"D_b", "0.01 + 0.001*x"}, {"dt", "0.1"}});
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  EXPECT_FALSE(sim->terms().any_time_dependent());
  opts.back() = {"D_b", "0.01*(1 + t)"};
  opts.push_back({"dt", "0.1"});
  auto timed = make_sim(PETSC_COMM_WORLD, opts);
  EXPECT_TRUE(timed->terms().any_time_dependent());
}

TEST(TimeVarying, ExplicitBoundExceededLaterIsUserError) {
  OptionList opts = no_reaction();
  opts.insert(opts.end(),
              {{"grid_n", "16,8"}, {"grid_L", "1"}, {"D_b", "0.001*(1 + t)"}, {"dt", "0.9"}});
  // Bound 2 / (D rho) with rho = 4 (256 + 64) = 1280: 1.5625 at t = 0, below 0.9 once
  // D > 0.001736, i.e. t > 0.736: after the second step (t = 0.9).
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  std::string msg;
  try {
    for (int n = 0; n < 5; ++n)
      sim->step();
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("-dt 0.9: at t = 0.9"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-force_dt"), std::string::npos) << msg;
  EXPECT_TRUE(all_ranks(!msg.empty()));
}
