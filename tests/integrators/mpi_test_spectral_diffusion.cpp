// The FFT/DCT diffusion solve (operators/spectral_solver.hpp, -diffusion_solver), on 1, 2
// and 4 ranks, pure diffusion (-params_s 0) with the split integrator (Crank-Nicolson):
//   1. one Fourier mode sin(2 pi m x / Lx) sin(2 pi q y / Ly) (periodic) or cosine mode
//      cos(pi m x / Lx) cos(pi q y / Ly) (zero flux) after N steps equals the closed form g^N,
//      g = (1 + c lambda / 2) / (1 - c lambda / 2), lambda the 5-point symbol (each axis
//      -4/h^2 sin^2(pi m / n), resp. sin^2(pi m / (2 n))), to 1e-12;
//   2. a rough field (uniform +-20 % noise, every mode) on non-square grids (2-D 5pt and 9pt,
//      periodic, zero flux and Dirichlet (DST-II, boundary data in b), a rotated constant tensor
//      with cross terms on a periodic grid; 3-D 7pt periodic and mixed periodic / zero flux /
//      Dirichlet), spectral against KSP at rtol 1e-13:
//      max difference <= 1e-10;
//   2b. the tridiagonal slow-axis solve (-diffusion_slow_axis tridiagonal, the default where
//      it applies) against the full transform (fft) on rough fields: 2-D 5pt / 9pt, periodic,
//      zero flux, Dirichlet and mixed, 3-D 7pt / 19pt / 27pt, Crank-Nicolson (Strang) and
//      backward Euler (Lie), grids where a rank holds only 2 planes: max difference <= 1e-12;
//      with a tensor's cross terms it is a UserError naming the option; in place on a ghosted
//      local vector it equals the global solve bit for bit and leaves the ghosts alone;
//   3. where it does not apply (pinned cells, varying coefficients, a tensor's cross terms on
//      zero-flux axes) auto uses KSP and -diffusion_solver spectral is a UserError naming the
//      option.
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"
#include "core/user_error.hpp"
#include "operators/tridiagonal_solver.hpp"

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

// Both species of two runs agree to tol everywhere, and still have structure to compare.
void expect_same_fields(Simulation& x, Simulation& y, double tol) {
  for (int s = 0; s < 2; ++s) {
    const auto a = gather_all(x.grid(), x.state()[s]);
    const auto b = gather_all(y.grid(), y.state()[s]);
    ASSERT_EQ(a.size(), b.size());
    double d = 0.0, spread = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
      d = std::max(d, std::fabs(a[i] - b[i]));
      spread = std::max(spread, std::fabs(a[i] - 1.0));
    }
    // (gather_all fills rank 0 only; the verdicts are reduced over the ranks)
    EXPECT_LT(max_over_ranks(d), tol) << "species " << s;
    EXPECT_GT(max_over_ranks(spread), 1e-3); // the field still has structure to compare
  }
}

} // namespace

// Max |a - g^steps mode(x, y)| over the grid for species a after `steps` steps.
double mode_error(const std::string& bc, int steps) {
  // 32 x 24 cells, L = 8 x 6 (h = 0.25), mode (m, q) = (3, 2), species a: D = 0.7.
  const bool periodic = bc == "periodic";
  const std::string mode =
      periodic ? "sin(2*pi*3*x/8)*sin(2*pi*2*y/6)" : "cos(pi*3*x/8)*cos(pi*2*y/6)";
  OptionList o = diffusion_case("32,24", "8,6", mode, "auto");
  o.push_back({"grid_bc", bc});
  auto sim = run(o, steps);
  EXPECT_TRUE(all_ranks(sim->diffusion_solver()->spectral(0)));
  const double h = 0.25, c = 0.05 * 0.7, f = periodic ? 1.0 : 0.5;
  const double lam =
      -4.0 / (h * h) *
      (std::pow(std::sin(f * M_PI * 3 / 32), 2) + std::pow(std::sin(f * M_PI * 2 / 24), 2));
  const double g = std::pow((1.0 + 0.5 * c * lam) / (1.0 - 0.5 * c * lam), steps);
  const Grid& grid = sim->grid();
  const Box& ob = grid.owned();
  const PetscScalar* a;
  VecGetArrayRead(sim->state()[0], &a);
  double err = 0.0;
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
      const double x = (i + 0.5) * h, y = (j + 0.5) * h;
      const double shape = periodic
                               ? std::sin(2 * M_PI * 3 * x / 8) * std::sin(2 * M_PI * 2 * y / 6)
                               : std::cos(M_PI * 3 * x / 8) * std::cos(M_PI * 2 * y / 6);
      err = std::max(err, std::fabs(a[grid.local_index(i, j, 0)] - g * shape));
    }
  VecRestoreArrayRead(sim->state()[0], &a);
  return max_over_ranks(err);
}

TEST(SpectralDiffusion, FourierModeMatchesTheClosedForm) {
  EXPECT_LT(mode_error("periodic", 6), 1e-12);
}

TEST(SpectralDiffusion, CosineModeMatchesTheClosedFormOnZeroFluxAxes) {
  EXPECT_LT(mode_error("neumann", 6), 1e-12);
}

TEST(SpectralDiffusion, AgreesWithKspOnRoughFields) {
  struct Case {
    const char *n, *L, *stencil, *bc;
    bool tensor;
  };
  for (const Case& k : {Case{"20,12", "5,3", "5pt", "periodic", false},
                        Case{"16,10", "4,2.5", "9pt", "periodic", false},
                        Case{"18,11", "4.5,2.75", "5pt", "neumann", false},
                        Case{"16,10", "4,2.5", "9pt", "neumann,periodic", false},
                        Case{"20,12", "5,3", "5pt", "periodic", true},
                        Case{"10,8,6", "2.5,2,1.5", "7pt", "periodic", false},
                        Case{"10,8,7", "2.5,2,1.75", "7pt", "periodic,neumann,periodic", false},
                        Case{"18,11", "4.5,2.75", "5pt", "dirichlet", false},
                        Case{"16,10", "4,2.5", "9pt", "dirichlet,periodic", false},
                        Case{"10,8,7", "2.5,2,1.75", "7pt", "neumann,dirichlet,periodic", false}}) {
    SCOPED_TRACE(std::string(k.n) + " " + k.stencil + " " + k.bc + (k.tensor ? " tensor" : ""));
    auto with = [&](const char* solver) {
      OptionList o = diffusion_case(k.n, k.L, "1 +- 20%", solver);
      o.push_back({"stencil", k.stencil});
      o.push_back({"grid_bc", k.bc});
      if (std::string(k.bc).find("dirichlet") != std::string::npos)
        o.insert(o.end(), {{"dirichlet_a", "0.7 + 0.2*x"}, {"dirichlet_b", "1.3"}});
      if (k.tensor)
        o.insert(o.end(), {{"diffusion", "tensor"},
                           {"tensor_theta", "0.4"},
                           {"tensor_l1", "1.6"},
                           {"tensor_l2", "0.5"}});
      return run(o, 4);
    };
    auto sp = with("spectral"), ksp = with("ksp");
    ASSERT_TRUE(all_ranks(sp->diffusion_solver()->spectral(0)));
    ASSERT_TRUE(all_ranks(sp->diffusion_solver()->spectral(1)));
    ASSERT_FALSE(ksp->diffusion_solver()->spectral(0));
    expect_same_fields(*sp, *ksp, 1e-10);
  }
}

TEST(SpectralDiffusion, TridiagonalAgreesWithTheFullTransform) {
  struct Case {
    const char *n, *L, *stencil, *bc, *ordering;
  };
  for (const Case& k : {Case{"20,12", "5,3", "5pt", "periodic", "strang"},
                        Case{"16,8", "4,2", "9pt", "periodic", "lie"},
                        Case{"18,11", "4.5,2.75", "5pt", "neumann", "strang"},
                        Case{"16,10", "4,2.5", "9pt", "neumann,periodic", "lie"},
                        Case{"17,12", "4.25,3", "5pt", "periodic,neumann", "strang"},
                        Case{"18,11", "4.5,2.75", "5pt", "dirichlet", "strang"},
                        Case{"12,8", "3,2", "5pt", "dirichlet,periodic", "lie"},
                        Case{"10,8,9", "2.5,2,2.25", "7pt", "periodic", "strang"},
                        Case{"8,8,8", "2,2,2", "19pt", "neumann", "lie"},
                        Case{"8,6,9", "2,1.5,2.25", "27pt", "periodic,neumann,periodic", "strang"},
                        Case{"10,8,8", "2.5,2,2", "7pt", "neumann,periodic,dirichlet", "lie"}}) {
    SCOPED_TRACE(std::string(k.n) + " " + k.stencil + " " + k.bc + " " + k.ordering);
    auto with = [&](const char* slow) {
      OptionList o = diffusion_case(k.n, k.L, "1 +- 20%", "spectral");
      o.insert(o.end(), {{"stencil", k.stencil},
                         {"grid_bc", k.bc},
                         {"split_ordering", k.ordering},
                         {"diffusion_slow_axis", slow}});
      if (std::string(k.bc).find("dirichlet") != std::string::npos)
        o.insert(o.end(), {{"dirichlet_a", "0.7 + 0.2*x"}, {"dirichlet_b", "1.3"}});
      return run(o, 4);
    };
    auto tri = with("tridiagonal"), fft = with("fft");
    expect_same_fields(*tri, *fft, 1e-12);
  }
  OptionList o = diffusion_case("20,12", "5,3", "1 +- 20%", "auto");
  o.insert(o.end(), {{"diffusion", "tensor"},
                     {"tensor_theta", "0.4"},
                     {"tensor_l1", "1.6"},
                     {"tensor_l2", "0.5"},
                     {"diffusion_slow_axis", "tridiagonal"}});
  try {
    run(o, 1);
    ADD_FAILURE() << "no UserError for -diffusion_slow_axis tridiagonal with cross terms";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("-diffusion_slow_axis tridiagonal"), std::string::npos);
  }
}

// The tridiagonal solve in place on a ghosted local vector (what the split integrator uses
// where the DMDA is split in slabs, its spectrum in the state's own planes) equals the solve of the
// owned cells in a global vector bit for bit and leaves the ghosts alone; 2-D odd and even rows
// (planes through the scratch plane or not), 3-D, Crank-Nicolson and backward Euler.
TEST(SpectralDiffusion, TridiagonalInPlaceOnTheLocalStateEqualsTheGlobalSolve) {
  struct Case {
    const char *n, *L, *stencil, *bc;
    double theta;
  };
  for (const Case& k :
       {Case{"8,40", "2,10", "5pt", "periodic", 0.5}, Case{"7,36", "1.75,9", "9pt", "neumann", 1.0},
        Case{"6,5,24", "1.5,1.25,6", "7pt", "periodic,neumann,periodic", 0.5},
        Case{"5,6,20", "1.25,1.5,5", "27pt", "neumann", 1.0},
        Case{"9,40", "2.25,10", "9pt", "periodic", 0.5},         // rows of n + 1 entries
        Case{"6,5,24", "1.5,1.25,6", "7pt", "periodic", 1.0}}) { // ghosts within a row
    SCOPED_TRACE(std::string(k.n) + " " + k.stencil + " " + k.bc);
    OptionList o = diffusion_case(k.n, k.L, "1 +- 20%", "spectral");
    o.insert(o.end(), {{"stencil", k.stencil}, {"grid_bc", k.bc}});
    auto sim = run(o, 0);
    const Grid& grid = sim->grid();
    std::string why;
    auto ts = TridiagonalSolver::create(grid, sim->diffusion_solver()->operators().M(0), &why);
    ASSERT_TRUE(all_ranks(ts != nullptr)) << why;
    ASSERT_TRUE(all_ranks(ts->steps_local())) << "the DMDA is not split in slabs";
    VecH local, global = grid.create_global();
    VecDuplicate(sim->state()[0], local.out());
    VecCopy(sim->state()[0], local);
    const Box& ob = grid.owned();
    std::vector<double> before;
    PetscScalar *l, *g;
    VecGetArray(local, &l);
    VecGetArray(global, &g);
    PetscInt nloc;
    VecGetLocalSize(local, &nloc);
    before.assign(l, l + nloc);
    for (PetscInt c = 0; c < ob.size(); ++c) { // owned cells, x fastest
      const PetscInt i = ob.s[0] + c % ob.m[0], j = ob.s[1] + c / ob.m[0] % ob.m[1],
                     kk = ob.s[2] + c / (ob.m[0] * ob.m[1]);
      g[grid.owned_index(i, j, kk)] = l[grid.local_index(i, j, kk)];
    }
    VecRestoreArray(global, &g);
    VecRestoreArray(local, &l);
    ts->step(global, 0.35, k.theta);
    ts->step_local(local, 0.35, k.theta);
    EXPECT_TRUE(all_ranks(ts->last_step_in_place())); // the spectrum in the state's own planes
    VecGetArray(local, &l);
    VecGetArray(global, &g);
    long differ = 0, ghosts_changed = 0, moved = 0;
    std::vector<char> owned(static_cast<size_t>(nloc), 0);
    for (PetscInt c = 0; c < ob.size(); ++c) {
      const PetscInt i = ob.s[0] + c % ob.m[0], j = ob.s[1] + c / ob.m[0] % ob.m[1],
                     kk = ob.s[2] + c / (ob.m[0] * ob.m[1]);
      const PetscInt li = grid.local_index(i, j, kk);
      owned[static_cast<size_t>(li)] = 1;
      differ += l[li] != g[grid.owned_index(i, j, kk)] ? 1 : 0;
      moved += l[li] != before[static_cast<size_t>(li)] ? 1 : 0;
    }
    for (PetscInt li = 0; li < nloc; ++li)
      ghosts_changed += !owned[static_cast<size_t>(li)] && l[li] != before[static_cast<size_t>(li)];
    VecRestoreArray(global, &g);
    VecRestoreArray(local, &l);
    EXPECT_TRUE(all_ranks(differ == 0)) << differ << " owned cells differ";
    EXPECT_TRUE(all_ranks(ghosts_changed == 0)) << ghosts_changed << " ghosts changed";
    EXPECT_TRUE(all_ranks(moved > ob.size() / 2)); // the step did change the field
  }
}

// Each case: auto falls back to KSP, -diffusion_solver spectral is a UserError naming it.
TEST(SpectralDiffusion, FallsBackWhereItDoesNotApply) {
  const std::vector<OptionList> cases = {{{"pin_a", "x < 1"}},
                                         {{"D_a", "0.5 + 0.2*x/3"}},
                                         {{"grid_bc", "neumann"},
                                          {"diffusion", "tensor"},
                                          {"tensor_theta", "0.4"},
                                          {"tensor_l1", "1.6"}}};
  for (const OptionList& extra : cases) {
    SCOPED_TRACE(extra.front().first + " " + extra.front().second);
    OptionList o = diffusion_case("12,10", "3,2.5", "1 +- 20%", "auto");
    o.insert(o.end(), extra.begin(), extra.end());
    auto sim = run(o, 1);
    EXPECT_FALSE(sim->diffusion_solver()->spectral(0));
    for (auto& [k, v] : o)
      if (k == "diffusion_solver") v = "spectral";
    try {
      run(o, 1);
      ADD_FAILURE() << "no UserError for -diffusion_solver spectral";
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find("-diffusion_solver spectral"), std::string::npos);
    }
  }
}
