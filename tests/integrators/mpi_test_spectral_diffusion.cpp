// The FFT diffusion solve (integrators/spectral_diffusion.hpp, -diffusion_solver), on 1 and
// 2 ranks, pure diffusion (-params_s 0) with the split integrator (Crank-Nicolson):
//   1. one Fourier mode sin(2 pi m x / Lx) sin(2 pi q y / Ly) after N steps equals the
//      closed form g^N, g = (1 + c lambda / 2) / (1 - c lambda / 2), lambda the 5-point
//      symbol -4/h^2 sin^2(pi m / n) (each axis), to 1e-12 (1 rank: spectral by default);
//   2. a rough field (uniform +-20 % noise, every mode) on non-square periodic grids (2-D 5pt and
//      9pt, 3-D 7pt), spectral against KSP at rtol 1e-13: max difference <= 1e-10;
//   3. where it does not apply (2 ranks, Neumann axes) auto uses KSP and -diffusion_solver
//      spectral is a UserError naming the option.
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"
#include "core/user_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

OptionList diffusion_case(const std::string& n, const std::string& L, const std::string& init,
                          const std::string& solver) {
  OptionList o = {{"grid_n", n},
                  {"grid_L", L},
                  {"params_s", "0"},
                  {"clamp", "false"},
                  {"D_a", "0.7"},
                  {"D_b", "0.3"},
                  {"init_a", init},
                  {"init_b", init},
                  {"dt", "0.05"},
                  {"integrator", "split"},
                  {"diffusion_solver", solver}};
  if (solver == "ksp") o.push_back({"diffusion_ksp_rtol", "1e-13"}); // (auto would pick KSP)
  return o;
}

std::unique_ptr<Simulation> run(OptionList opts, int steps) {
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  for (int i = 0; i < steps; ++i)
    sim->step();
  return sim;
}

} // namespace

TEST(SpectralDiffusion, FourierModeMatchesTheClosedForm) {
  if (comm_size() > 1) GTEST_SKIP() << "the FFT solve is serial";
  // 32 x 24 cells, L = 8 x 6 (h = 0.25), mode (m, q) = (3, 2), species a: D = 0.7.
  const int steps = 6;
  auto sim = run(diffusion_case("32,24", "8,6", "sin(2*pi*3*x/8)*sin(2*pi*2*y/6)", "auto"), steps);
  ASSERT_TRUE(sim->diffusion_solver()->spectral(0));
  const double h = 0.25, c = 0.05 * 0.7;
  const double lam = -4.0 / (h * h) *
                     (std::pow(std::sin(M_PI * 3 / 32), 2) + std::pow(std::sin(M_PI * 2 / 24), 2));
  const double g = std::pow((1.0 + 0.5 * c * lam) / (1.0 - 0.5 * c * lam), steps);
  const Grid& grid = sim->grid();
  const Box& ob = grid.owned();
  const PetscScalar* a;
  VecGetArrayRead(sim->state()[0], &a);
  double err = 0.0;
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      const double x = (i + 0.5) * h, y = (j + 0.5) * h;
      const double exact = g * std::sin(2 * M_PI * 3 * x / 8) * std::sin(2 * M_PI * 2 * y / 6);
      err = std::max(err, std::fabs(a[grid.local_index(i, j, 0)] - exact));
    }
  VecRestoreArrayRead(sim->state()[0], &a);
  EXPECT_LT(err, 1e-12);
}

TEST(SpectralDiffusion, AgreesWithKspOnRoughFields) {
  if (comm_size() > 1) GTEST_SKIP() << "the FFT solve is serial";
  struct Case {
    const char *n, *L, *stencil;
  };
  for (const Case& k : {Case{"20,12", "5,3", "5pt"}, Case{"16,10", "4,2.5", "9pt"},
                        Case{"10,8,6", "2.5,2,1.5", "7pt"}}) {
    SCOPED_TRACE(std::string(k.n) + " " + k.stencil);
    auto with = [&](const char* solver) {
      OptionList o = diffusion_case(k.n, k.L, "1 +- 20%", solver);
      o.push_back({"stencil", k.stencil});
      return run(o, 4);
    };
    auto sp = with("spectral"), ksp = with("ksp");
    ASSERT_TRUE(sp->diffusion_solver()->spectral(0));
    ASSERT_TRUE(sp->diffusion_solver()->spectral(1));
    ASSERT_FALSE(ksp->diffusion_solver()->spectral(0));
    for (int s = 0; s < 2; ++s) {
      const auto a = gather_all(sp->grid(), sp->state()[s]);
      const auto b = gather_all(ksp->grid(), ksp->state()[s]);
      ASSERT_EQ(a.size(), b.size());
      double d = 0.0, spread = 0.0;
      for (size_t i = 0; i < a.size(); ++i) {
        d = std::max(d, std::fabs(a[i] - b[i]));
        spread = std::max(spread, std::fabs(a[i] - 1.0));
      }
      EXPECT_LT(d, 1e-10) << "species " << s;
      EXPECT_GT(spread, 1e-3); // the field still has structure to compare
    }
  }
}

TEST(SpectralDiffusion, FallsBackWhereItDoesNotApply) {
  OptionList neumann = diffusion_case("12,10", "3,2.5", "1 +- 20%", "auto");
  neumann.push_back({"grid_bc", "neumann"});
  auto sim = run(neumann, 1);
  EXPECT_FALSE(sim->diffusion_solver()->spectral(0));
  OptionList forced = neumann;
  forced.back() = {"grid_bc", "neumann"};
  for (auto& [k, v] : forced)
    if (k == "diffusion_solver") v = "spectral";
  try {
    run(forced, 1);
    ADD_FAILURE() << "no UserError for -diffusion_solver spectral on a Neumann grid";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("-diffusion_solver spectral"), std::string::npos);
  }
  if (comm_size() > 1) { // periodic, but parallel: KSP
    auto par = run(diffusion_case("12,10", "3,2.5", "1 +- 20%", "auto"), 1);
    EXPECT_FALSE(par->diffusion_solver()->spectral(0));
  }
}
