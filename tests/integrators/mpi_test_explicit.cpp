// Explicit integrator: (1) bitwise identical results on PETSC_COMM_WORLD and on one rank
// (PETSC_COMM_SELF) for 2-D and 3-D decks with random fields, every boundary type and both 2-D
// stencils; (2) a Fourier mode of pure diffusion decays exactly as the discrete symbol says
// (relative 1e-12); (3) Dirichlet boundaries converge to the exact linear steady state (1e-8);
// (4) zero-flux and periodic boundaries conserve mass (relative 1e-12).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

std::vector<std::vector<double>> run_and_gather(MPI_Comm comm, const OptionList& opts, int steps) {
  auto sim = make_sim(comm, opts);
  for (int n = 0; n < steps; ++n)
    sim->step();
  std::vector<std::vector<double>> out;
  for (auto& v : sim->state())
    out.push_back(gather_all(sim->grid(), v));
  return out;
}

bool bitwise_equal_on_one_and_world(const OptionList& opts, int steps) {
  const auto world = run_and_gather(PETSC_COMM_WORLD, opts, steps);
  const auto self = run_and_gather(PETSC_COMM_SELF, opts, steps);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  bool ok = true;
  if (rank == 0) {
    EXPECT_EQ(world.size(), self.size());
    for (size_t s = 0; s < world.size(); ++s) {
      EXPECT_EQ(world[s].size(), self[s].size());
      const bool same =
          world[s].size() == self[s].size() &&
          std::memcmp(world[s].data(), self[s].data(), world[s].size() * sizeof(double)) == 0;
      EXPECT_TRUE(same) << "species " << s << " differs between " << comm_size()
                        << " ranks and 1 rank";
      ok = ok && same;
      // The run must actually have evolved (not a trivially constant field).
      double mn = world[s][0], mx = world[s][0];
      for (double v : world[s])
        mn = std::min(mn, v), mx = std::max(mx, v);
      EXPECT_GT(mx - mn, 1e-6);
    }
  }
  return all_ranks(ok);
}

} // namespace

TEST(ExplicitEquivalence, Turing2DPeriodicGaussianParams) {
  EXPECT_TRUE(bitwise_equal_on_one_and_world({{"grid_n", "45,38"},
                                              {"params_alpha", "12 +- 0.1% gauss"},
                                              {"params_beta", "16 +- 0.1% gauss"},
                                              {"init_a", "4 +- 1%"},
                                              {"dt", "0.5"}},
                                             300));
}

TEST(ExplicitEquivalence, Turing2DNineNeumannDirichlet) {
  EXPECT_TRUE(bitwise_equal_on_one_and_world({{"grid_n", "40,33"},
                                              {"grid_bc", "neumann,dirichlet"},
                                              {"stencil", "9pt"},
                                              {"dirichlet_a", "4 + sin(2*pi*x/Lx)"},
                                              {"params_beta", "15.85 + 0.5*y/Ly"},
                                              {"init_b", "4 +- 2% gauss"},
                                              {"dt", "0.5"}},
                                             300));
}

TEST(ExplicitEquivalence, Turing3DMixedBoundaries) {
  EXPECT_TRUE(bitwise_equal_on_one_and_world({{"grid_n", "17,14,12"},
                                              {"grid_bc", "periodic,neumann,dirichlet"},
                                              {"params_alpha", "12 +- 0.5%"},
                                              {"init_a", "4 +- 1% gauss"},
                                              {"dt", "0.5"}},
                                             100));
}

TEST(ExplicitDiffusion, FourierModeDecaysAsDiscreteSymbol) {
  const double Lx = 4, Ly = 3, D = 0.01;
  const PetscInt nx = 32, ny = 24;
  const double hx = Lx / nx, hy = Ly / ny, kx = 2 * M_PI / Lx, ky = 2 * M_PI * 2 / Ly;
  const double lambda = -4 / (hx * hx) * std::pow(std::sin(kx * hx / 2), 2) -
                        4 / (hy * hy) * std::pow(std::sin(ky * hy / 2), 2);
  const double dt = 0.9 * hx * hx / (4 * D);
  const int steps = 400;
  auto sim = make_sim(PETSC_COMM_WORLD, {{"grid_n", "32,24"},
                                         {"grid_L", "4,3"},
                                         {"params_s", "0"},
                                         {"clamp", "false"},
                                         {"D_a", "0.01"},
                                         {"D_b", "0.01"},
                                         {"init_a", "1 + sin(2*pi*x/Lx)*cos(4*pi*y/Ly)"},
                                         {"dt", std::to_string(dt)}});
  for (int n = 0; n < steps; ++n)
    sim->step();
  const double amp = std::pow(1 + sim->dt() * D * lambda, steps);
  ASSERT_LT(amp, 0.9); // the mode really decayed
  const auto a = gather_all(sim->grid(), sim->state()[0]);
  double err = 0;
  for (PetscInt j = 0; j < ny && !a.empty(); ++j)
    for (PetscInt i = 0; i < nx; ++i) {
      const double x = (i + 0.5) * hx, y = (j + 0.5) * hy;
      err =
          std::max(err, std::abs(a[i + nx * j] - (1 + amp * std::sin(kx * x) * std::cos(ky * y))));
    }
  EXPECT_LT(max_over_ranks(err), 1e-12);
}

TEST(ExplicitDiffusion, DirichletLinearSteadyState) {
  auto sim = make_sim(PETSC_COMM_WORLD, {{"grid_n", "16,6"},
                                         {"grid_bc", "dirichlet,periodic"},
                                         {"params_s", "0"},
                                         {"clamp", "false"},
                                         {"D_a", "1"},
                                         {"D_b", "1"},
                                         {"dirichlet_a", "1 + 2*x/Lx"},
                                         {"init_a", "0"},
                                         {"dt", "0.2"}});
  for (int n = 0; n < 5000; ++n)
    sim->step();
  const auto a = gather_all(sim->grid(), sim->state()[0]);
  double err = 0;
  for (size_t c = 0; c < a.size(); ++c) {
    const double x = (static_cast<double>(c % 16) + 0.5);
    err = std::max(err, std::abs(a[c] - (1 + 2 * x / 16)));
  }
  EXPECT_LT(max_over_ranks(err), 1e-8);
}

TEST(ExplicitDiffusion, NeumannAndPeriodicConserveMass) {
  for (const char* stencil : {"5pt", "9pt"})
    for (const char* bc : {"neumann", "periodic", "neumann,periodic"}) {
      auto sim = make_sim(PETSC_COMM_WORLD, {{"grid_n", "20,14"},
                                             {"grid_bc", bc},
                                             {"stencil", stencil},
                                             {"params_s", "0"},
                                             {"clamp", "false"},
                                             {"init_a", "noise()"},
                                             {"dt", "0.5"}});
      const auto a0 = gather_all(sim->grid(), sim->state()[0]);
      for (int n = 0; n < 500; ++n)
        sim->step();
      const auto a1 = gather_all(sim->grid(), sim->state()[0]);
      double m0 = 0, m1 = 0, var0 = 0, var1 = 0;
      for (double v : a0)
        m0 += v;
      for (double v : a1)
        m1 += v;
      for (double v : a0)
        var0 += (v - m0 / a0.size()) * (v - m0 / a0.size());
      for (double v : a1)
        var1 += (v - m1 / a1.size()) * (v - m1 / a1.size());
      const double rel = a0.empty() ? 0 : std::abs(m1 - m0) / m0;
      EXPECT_LT(max_over_ranks(rel), 1e-12) << stencil << " " << bc;
      if (!a0.empty()) {
        EXPECT_LT(var1, 0.1 * var0) << "diffusion did not smooth the noise";
      }
    }
}
