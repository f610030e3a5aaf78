// Terms and constraints of a run through the Simulation, with every integrator:
// (1) pinned cells (-pin_S) keep their initial values bitwise while the rest evolves
//     (explicit, split, TS with implicit and with explicit diffusion);
// (2) a parameter using t against a closed form: Gray-Scott with a = 0 is
//     db/dt = F(t) (1 - b), so b(T) = 1 - (1 - b0) exp(-int_0^T F) with F = 0.01 + 0.01 t;
//     explicit Euler converges with order 1, split (Strang, parameter at the midpoint) and TS
//     (ARKIMEX 2E, parameter at the stage times) with order 2;
// (3) a parameter that leaves its range at a later t stops the run with the key and t.
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "core/user_error.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

OptionList pinned_run(const OptionList& integrator) {
  OptionList opts = {
      {"model", "turing"},    {"grid_n", "32,24"},    {"grid_bc", "neumann,periodic"},
      {"init_a", "4 +- 30%"}, {"init_b", "4 +- 30%"}, {"pin_a", "j < 2 || (i > 10 && i < 14)"},
      {"pin_b", "i == 31"},   {"dt", "0.5"},          {"summary", "false"}};
  opts.insert(opts.end(), integrator.begin(), integrator.end());
  return opts;
}

bool is_pinned(int s, PetscInt i, PetscInt j) {
  return s == 0 ? (j < 2 || (i > 10 && i < 14)) : i == 31;
}

// Largest change of pinned and of free cells over `steps` steps (all ranks).
void pinned_change(const OptionList& integrator, int steps, double& pinned, double& free) {
  auto sim = make_sim(PETSC_COMM_WORLD, pinned_run(integrator));
  std::vector<std::vector<double>> before;
  for (int s = 0; s < 2; ++s)
    before.push_back(gather_all(sim->grid(), sim->state()[s]));
  for (int n = 0; n < steps; ++n)
    sim->step();
  pinned = free = 0;
  for (int s = 0; s < 2; ++s) {
    const auto after = gather_all(sim->grid(), sim->state()[s]);
    for (size_t c = 0; c < after.size(); ++c) {
      const double d = std::abs(after[c] - before[s][c]);
      double& m = is_pinned(s, static_cast<PetscInt>(c % 32), static_cast<PetscInt>(c / 32))
                      ? pinned
                      : free;
      m = std::max(m, d);
    }
  }
  MPI_Bcast(&pinned, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  MPI_Bcast(&free, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
}

} // namespace

TEST(RunTerms, PinnedCellsHeldByEveryIntegrator) {
  const std::vector<OptionList> integrators = {
      {{"integrator", "explicit"}},
      {{"integrator", "split"}},
      {{"integrator", "split"}, {"split_ordering", "lie"}},
      {{"integrator", "ts"}},
      {{"integrator", "ts"}, {"ts_diffusion", "explicit"}, {"ts_type", "rk"}}};
  for (const auto& integ : integrators) {
    double pinned = -1, free = -1;
    pinned_change(integ, 40, pinned, free);
    PetscPrintf(PETSC_COMM_WORLD, "  -integrator %s%s: pinned cells moved %g, free cells %g\n",
                integ[0].second.c_str(), integ.size() > 1 ? " (variant)" : "", pinned, free);
    EXPECT_EQ(pinned, 0.0) << integ[0].second;
    EXPECT_GT(free, 1e-3) << integ[0].second;
  }
}

namespace {

// Gray-Scott at a = 0 with F(t) = 0.01 + 0.01 t from b = 0.2: error of b at T = 10.
double timed_error(const OptionList& integrator, double dt) {
  const double T = 10;
  OptionList opts = {{"model", "gray_scott"},
                     {"grid_n", "8,8"},
                     {"init_a", "0"},
                     {"init_b", "0.2"},
                     {"params_F", "0.01 + 0.01*t"},
                     {"dt", std::to_string(dt)},
                     {"summary", "false"}};
  opts.insert(opts.end(), integrator.begin(), integrator.end());
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int n = 0; n < steps; ++n)
    sim->step();
  const double exact = 1 - 0.8 * std::exp(-(0.01 * T + 0.005 * T * T));
  const auto b = gather_all(sim->grid(), sim->state()[1]);
  double err = 0;
  for (double v : b)
    err = std::max(err, std::abs(v - exact));
  MPI_Bcast(&err, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  return err;
}

double timed_order(const OptionList& integrator, const char* label) {
  const double e1 = timed_error(integrator, 0.2), e2 = timed_error(integrator, 0.1);
  const double order = std::log2(e1 / e2);
  PetscPrintf(PETSC_COMM_WORLD, "  %s: error %.3e (dt 0.2), %.3e (dt 0.1), order %.3f\n", label, e1,
              e2, order);
  return order;
}

} // namespace

TEST(RunTerms, TimeDependentParameterClosedForm) {
  EXPECT_NEAR(timed_order({{"integrator", "explicit"}}, "explicit"), 1.0, 0.1);
  EXPECT_NEAR(timed_order({{"integrator", "split"}}, "split (strang)"), 2.0, 0.15);
  EXPECT_NEAR(timed_order({{"integrator", "ts"}}, "ts (arkimex 2e)"), 2.0, 0.15);
  EXPECT_LT(timed_error({{"integrator", "ts"}}, 0.1), 1e-4);
}

TEST(RunTerms, ParameterLeavingItsRangeLaterIsUserError) {
  auto sim = make_sim(PETSC_COMM_WORLD, {{"model", "gray_scott"},
                                         {"grid_n", "8,8"},
                                         {"params_F", "0.5 + 0.1*t"},
                                         {"dt", "1"},
                                         {"summary", "false"}});
  std::string msg;
  try {
    for (int n = 0; n < 10; ++n)
      sim->step();
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("-params_F"), std::string::npos) << msg;
  EXPECT_NE(msg.find("t = 6"), std::string::npos) << msg;
  EXPECT_TRUE(all_ranks(!msg.empty()));
}
