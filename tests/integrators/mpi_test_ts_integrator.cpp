// PETSc TS integrator (ARKIMEX 2e, diffusion implicit, reaction and sources explicit):
// (1) a Fourier mode of pure diffusion decays as exp(D lambda_h T) with the discrete
//     eigenvalue lambda_h of the 5-point stencil, and the temporal order is 2;
// (2) a manufactured Schnakenberg solution (time-dependent sources through SourceTerms, built
//     on a Fourier mode so that the spatial discretisation is exact) converges with order 2,
//     and so do successive differences of a plain Schnakenberg run;
// (3) results on PETSC_COMM_WORLD and PETSC_COMM_SELF agree to 1e-10 relative (2-D and 3-D,
//     periodic, Neumann and Dirichlet boundaries, spatially varying parameters);
// (4) Dirichlet data (the b vector) gives the exact linear steady state;
// (5) -ts_adapt_type basic takes several internal steps per step() call and stays accurate;
// (6) a failed linear solve, and an error inside a callback, are UserErrors on every rank;
// (7) other schemes from the options database: -ts_arkimex_type 3 (order 3), -ts_type bdf
//     (order 2: history kept across step() calls), -ts_type cn (order 2: Newton by default);
//     explicit types are refused; the clamp floor holds (and restarts the TS).
#include "../mpi_expect.hpp"
#include "../sim_fixture.hpp"

#include "app/model_registry.hpp"
#include "core/user_error.hpp"
#include "integrators/ts_integrator.hpp"
#include "operators/pointwise_terms.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>

using namespace morphogen;
using namespace morphogen::testing;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Initial value of species s at cell centre (x, y, z) of global cell (i, j, k).
using InitFn =
    std::function<double(int s, double x, double y, double z, PetscInt i, PetscInt j, PetscInt k)>;

struct ProblemSpec {
  int dim = 2;
  PetscInt nx = 16, ny = 16, nz = 1;
  double Lx = 1, Ly = 1, Lz = 1;
  Boundary bcx = Boundary::Periodic, bcy = Boundary::Periodic, bcz = Boundary::Periodic;
  std::string model = "schnakenberg";
  std::vector<double> params; // scalar values (empty: the model's defaults)
  // Non-null: every parameter is a field with these values.
  std::function<double(int q, double x, double y, double z)> param_field;
  std::vector<double> D;
  std::vector<double> floor;     // empty: no clamp
  std::vector<double> dirichlet; // per species, constant face value
  InitFn init;
  double dt = 0.1;
  OptionList options; // PETSc options (-source_*, -ts_*, ...)
  bool implicit_diffusion = true;
};

// Members are destroyed in reverse order: the integrator first, the grid last.
struct Problem {
  std::unique_ptr<Grid> grid;
  std::unique_ptr<Halo> halo;
  Stencil stencil;
  std::vector<FaceValues> dirichlet;
  std::vector<std::unique_ptr<DiffusionOperator>> ops;
  std::unique_ptr<OperatorMatrices> lap;
  // The species' constant isotropic operators as matrices (dirichlet: may be null).
  void build_matrices(const std::vector<double>& D, const std::vector<FaceValues>* dirichlet) {
    ops.clear();
    std::vector<const DiffusionOperator*> ptr;
    for (double d : D) {
      ops.push_back(std::make_unique<DiffusionOperator>(*grid, stencil, d));
      ptr.push_back(ops.back().get());
    }
    lap = std::make_unique<OperatorMatrices>(*grid, *halo, stencil, ptr, dirichlet);
  }
  ParamSet params;
  std::unique_ptr<SourceTerms> sources;
  std::vector<VecH> u;
  std::vector<std::string> species;
  std::string model;
  std::unique_ptr<TermList> terms;
  std::unique_ptr<TsIntegrator> ts;
  // The run's terms (diffusion, reaction, sources, clamp) and the TS integrator on them;
  // implicit: diffusion in the implicit part (else in the right-hand side).
  void build_ts(const std::vector<double>& floor, double dt, bool implicit = true) {
    ts.reset();
    terms = std::make_unique<TermList>();
    const ModelEntry* m = find_model(model);
    for (size_t s = 0; s < ops.size(); ++s)
      terms->add(std::make_unique<DiffusionTerm>(static_cast<int>(s), species[s], *ops[s]));
    terms->add(std::make_unique<ReactionTerm>(*grid, model, m->rates, m->nspecies, params));
    if (sources->any()) terms->add(std::make_unique<SourceTerm>(*grid, *sources, species));
    terms->add(std::make_unique<ClampFloor>(*grid, floor));
    ts = std::make_unique<TsIntegrator>(*grid, *halo, species, *terms,
                                        implicit ? lap.get() : nullptr,
                                        dirichlet.empty() ? nullptr : &dirichlet, dt);
  }
  double t = 0;
  PetscInt nstep = 0;

  void run(int steps, double dt) {
    for (int n = 0; n < steps; ++n) {
      ts->step(u, t, dt, nstep + 1);
      ++nstep;
      t = nstep * dt;
    }
  }
  // Largest |u_s - f(x, y)| over all cells (every rank gets the value).
  double max_error(int s, const std::function<double(double, double)>& f) const {
    const Box& ob = grid->owned();
    const PetscScalar* a;
    VecGetArrayRead(u[s], &a);
    double err = 0;
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
          err = std::max(err, std::abs(a[grid->local_index(i, j, k)] -
                                       f(grid->centre(0, i), grid->centre(1, j))));
    VecRestoreArrayRead(u[s], &a);
    double g = 0;
    MPI_Allreduce(&err, &g, 1, MPI_DOUBLE, MPI_MAX, grid->comm());
    return g;
  }
};

std::unique_ptr<Problem> make_problem(MPI_Comm comm, const ProblemSpec& ps) {
  set_options(ps.options);
  auto p = std::make_unique<Problem>();
  const ModelEntry* model = find_model(ps.model);
  if (!model) throw std::logic_error("no model " + ps.model);
  GridSpec spec;
  spec.dim = ps.dim;
  spec.n = {ps.nx, ps.ny, ps.nz};
  spec.L = {ps.Lx, ps.Ly, ps.Lz};
  spec.bc = {ps.bcx, ps.bcy, ps.bcz};
  spec.stencil_width = 1;
  spec.box_stencil = false;
  p->grid = std::make_unique<Grid>(comm, spec);
  p->halo = std::make_unique<Halo>(*p->grid);
  const GridSpec& gs = p->grid->spec();
  const double h[3] = {gs.h(0), gs.h(1), gs.h(2)};
  if (!make_stencil(ps.dim == 2 ? "5pt" : "7pt", ps.dim, h, p->stencil))
    throw std::logic_error("stencil");
  const Boundary bc[3] = {ps.bcx, ps.bcy, ps.bcz};
  const int ns = model->nspecies;
  std::vector<std::string> species;
  for (int s = 0; s < ns; ++s)
    species.emplace_back(model->species[s].name);
  bool any_dirichlet = false;
  for (int d = 0; d < ps.dim; ++d)
    any_dirichlet |= bc[d] == Boundary::Dirichlet;
  if (any_dirichlet) {
    p->dirichlet.assign(ns, FaceValues{});
    for (int s = 0; s < ns; ++s)
      for (int d = 0; d < ps.dim; ++d)
        if (bc[d] == Boundary::Dirichlet)
          for (int side = 0; side < 2; ++side)
            p->dirichlet[s].face[2 * d + side].assign(static_cast<size_t>(p->halo->face_size(d)),
                                                      ps.dirichlet.at(s));
  }
  p->build_matrices(ps.D, any_dirichlet ? &p->dirichlet : nullptr);
  const Box& ob = p->grid->owned();
  for (int q = 0; q < model->nparams; ++q) {
    p->params.names.emplace_back(model->params[q].name);
    const double v = ps.params.empty() ? model->params[q].def : ps.params.at(q);
    if (ps.param_field) {
      VecH f = p->grid->create_global();
      PetscScalar* a;
      VecGetArray(f, &a);
      for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
        for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
          for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
            a[p->grid->owned_index(i, j, k)] = ps.param_field(
                q, p->grid->centre(0, i), p->grid->centre(1, j), p->grid->centre(2, k));
      VecRestoreArray(f, &a);
      p->params.scalar.push_back(std::nan(""));
      p->params.field.push_back(std::move(f));
    } else {
      p->params.scalar.push_back(v);
      p->params.field.emplace_back();
    }
  }
  Options opt(comm);
  p->sources = std::make_unique<SourceTerms>(*p->grid, opt, species, 1, "");
  for (int s = 0; s < ns; ++s) {
    p->u.push_back(p->grid->create_local());
    PetscScalar* a;
    VecGetArray(p->u.back(), &a);
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
        for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
          a[p->grid->local_index(i, j, k)] = ps.init(
              s, p->grid->centre(0, i), p->grid->centre(1, j), p->grid->centre(2, k), i, j, k);
    VecRestoreArray(p->u.back(), &a);
  }
  const std::vector<double> floor = ps.floor.empty() ? std::vector<double>(ns, -kInf) : ps.floor;
  p->species = species;
  p->model = ps.model;
  p->build_ts(floor, ps.dt, ps.implicit_diffusion);
  return p;
}

// Least-squares slope of log(err) against log(dt).
double fitted_order(const std::vector<double>& dts, const std::vector<double>& errs) {
  const size_t n = dts.size();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t k = 0; k < n; ++k) {
    const double x = std::log(dts[k]), y = std::log(errs[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Fitted order of the error at time T over `levels` runs with dt0, dt0/2, ...
double measure_order(const char* label, const std::function<ProblemSpec(double)>& spec,
                     const std::function<double(Problem&)>& error, double T, double dt0, int levels,
                     std::vector<double>* errors = nullptr) {
  std::vector<double> dts, errs;
  for (int r = 0; r < levels; ++r) {
    const double dt = dt0 / (1 << r);
    auto p = make_problem(PETSC_COMM_WORLD, spec(dt));
    p->run(static_cast<int>(std::lround(T / dt)), dt);
    dts.push_back(dt);
    errs.push_back(error(*p));
    PetscPrintf(PETSC_COMM_WORLD, "  %s, dt = %-9g error %.4e\n", label, dt, errs.back());
  }
  const double order = fitted_order(dts, errs);
  PetscPrintf(PETSC_COMM_WORLD, "  %s: fitted temporal order %.4f\n", label, order);
  if (errors) *errors = errs;
  return order;
}

std::string num(double v) {
  std::ostringstream o;
  o.precision(17);
  o << v;
  return o.str();
}

// Pure diffusion (Turing with s = 0) of a Fourier mode on a periodic 4 x 3 domain, 32 x 24 cells.
struct DiffusionMode {
  static constexpr double Lx = 4, Ly = 3, D = 0.05, T = 1;
  static constexpr PetscInt nx = 32, ny = 24;
  double kx = 2 * M_PI / Lx, ky = 2 * M_PI * 2 / Ly;
  double lambda() const { // discrete eigenvalue (negative)
    const double hx = Lx / nx, hy = Ly / ny;
    return -4 / (hx * hx) * std::pow(std::sin(kx * hx / 2), 2) -
           4 / (hy * hy) * std::pow(std::sin(ky * hy / 2), 2);
  }
  double mode(double x, double y) const { return std::sin(kx * x) * std::cos(ky * y); }
  ProblemSpec spec(double dt, const OptionList& options = {}) const {
    ProblemSpec ps;
    ps.nx = nx, ps.ny = ny, ps.Lx = Lx, ps.Ly = Ly;
    ps.model = "turing";
    ps.params = {12, 16, 0};
    ps.D = {D, D};
    ps.init = [this](int s, double x, double y, double, PetscInt, PetscInt, PetscInt) {
      return s == 0 ? 1 + mode(x, y) : 4.0;
    };
    ps.dt = dt;
    ps.options = options;
    return ps;
  }
  // Max error of species a against the exact discrete-in-space solution at time T.
  double error(Problem& p) const {
    const double amp = std::exp(D * lambda() * T);
    return p.max_error(0, [&](double x, double y) { return 1 + amp * mode(x, y); });
  }
};

} // namespace

TEST(TsIntegrator, DiffusionModeMatchesDiscreteEigenvalue) {
  DiffusionMode m;
  ASSERT_LT(std::exp(m.D * m.lambda() * m.T), 0.5); // the mode really decays
  const double dt = 0.002;
  auto p = make_problem(PETSC_COMM_WORLD, m.spec(dt));
  const int steps = static_cast<int>(std::lround(m.T / dt));
  p->run(steps, dt);
  const double err = m.error(*p);
  EXPECT_LT(err, 1e-6);
  EXPECT_EQ(p->ts->total_steps(), steps); // fixed dt: one TS step per call
  EXPECT_EQ(p->ts->total_rejected(), 0);
  // Species b (constant) stays constant.
  EXPECT_LT(p->max_error(1, [](double, double) { return 4.0; }), 1e-12);
  PetscPrintf(PETSC_COMM_WORLD, "  diffusion mode, dt = %g: max error %.3e\n", dt, err);
}

TEST(TsIntegrator, DiffusionModeSecondOrderInTime) {
  DiffusionMode m;
  const double order = measure_order(
      "diffusion mode", [&](double dt) { return m.spec(dt); },
      [&](Problem& p) { return m.error(p); }, m.T, 0.1, 5);
  EXPECT_NEAR(order, 2.0, 0.1);
}

namespace {

// Manufactured Schnakenberg solution on a periodic 2 pi x 2 pi grid (24 x 24 cells):
//   u* = 1 + 0.2 cos(t) phi,  v* = 0.9 + 0.1 sin(t) phi,  phi = sin(x) cos(2 y).
// phi is an eigenvector of the discrete Laplacian (eigenvalue lambda_h), so u*, v* solve the
// semi-discrete system exactly with the sources
//   S_u = du*/dt - D_u lambda_h (u* - 1)   - gamma (a - u* + u*^2 v*)
//   S_v = dv*/dt - D_v lambda_h (v* - 0.9) - gamma (b - u*^2 v*)
// and the error at T is purely temporal.
struct Manufactured {
  static constexpr double L = 2 * M_PI, Du = 0.05, Dv = 1.0, T = 1;
  static constexpr PetscInt n = 24;
  double lambda() const {
    const double h = L / n;
    return -4 / (h * h) * (std::pow(std::sin(h / 2), 2) + std::pow(std::sin(2 * h / 2), 2));
  }
  static double phi(double x, double y) { return std::sin(x) * std::cos(2 * y); }
  static double u_exact(double x, double y, double t) { return 1 + 0.2 * std::cos(t) * phi(x, y); }
  static double v_exact(double x, double y, double t) {
    return 0.9 + 0.1 * std::sin(t) * phi(x, y);
  }
  ProblemSpec spec(double dt, const OptionList& extra = {}) const {
    const std::string ph = "(sin(x)*cos(2*y))";
    const std::string us = "(1+0.2*cos(t)*" + ph + ")", vs = "(0.9+0.1*sin(t)*" + ph + ")";
    const std::string lam = num(lambda());
    // a = 0.1, b = 0.9, gamma = 1 (defaults)
    const std::string Su = "-0.2*sin(t)*" + ph + "-" + num(Du) + "*(" + lam + ")*0.2*cos(t)*" + ph +
                           "-(0.1-" + us + "+" + us + "^2*" + vs + ")";
    const std::string Sv = "0.1*cos(t)*" + ph + "-" + num(Dv) + "*(" + lam + ")*0.1*sin(t)*" + ph +
                           "-(0.9-" + us + "^2*" + vs + ")";
    ProblemSpec ps;
    ps.nx = ps.ny = n;
    ps.Lx = ps.Ly = L;
    ps.model = "schnakenberg";
    ps.D = {Du, Dv};
    ps.init = [](int s, double x, double y, double, PetscInt, PetscInt, PetscInt) {
      return s == 0 ? u_exact(x, y, 0) : v_exact(x, y, 0);
    };
    ps.dt = dt;
    ps.options = {{"source_u", Su}, {"source_v", Sv}};
    ps.options.insert(ps.options.end(), extra.begin(), extra.end());
    return ps;
  }
  double error(Problem& p) const {
    return std::max(p.max_error(0, [&](double x, double y) { return u_exact(x, y, T); }),
                    p.max_error(1, [&](double x, double y) { return v_exact(x, y, T); }));
  }
};

} // namespace

TEST(TsIntegrator, SchnakenbergManufacturedSecondOrder) {
  Manufactured m;
  std::vector<double> errs;
  const double order = measure_order(
      "Schnakenberg MMS", [&](double dt) { return m.spec(dt); },
      [&](Problem& p) { return m.error(p); }, m.T, 0.05, 5, &errs);
  EXPECT_NEAR(order, 2.0, 0.1);
  EXPECT_LT(errs.back(), 1e-6);
}

TEST(TsIntegrator, SchnakenbergSuccessiveDifferencesSecondOrder) {
  // No sources: a smooth two-mode start on a periodic 16 x 16 grid of unit spacing, the
  // model's D_u = 1, D_v = 20; orders from successive differences |u_dt - u_dt/2|. The
  // diffusion of v is stiff here (dt D_v rho(L) = 16 at dt = 0.1) and the stage order of
  // ARKIMEX 2e is 1, so larger steps show a mild order reduction (ratios 3.6, 3.8, 3.9 from
  // dt = 0.1); from dt = 0.025 down the ratios are 3.9-4.0. With D = (0.05, 1) the order is
  // 1.99 from dt = 0.1.
  ProblemSpec ps;
  ps.nx = ps.ny = 16;
  ps.Lx = ps.Ly = 16;
  ps.D = {1.0, 20.0};
  ps.init = [](int s, double x, double y, double, PetscInt, PetscInt, PetscInt) {
    const double k = 2 * M_PI / 16;
    return s == 0 ? 1 + 0.3 * std::sin(k * x) * std::cos(2 * k * y)
                  : 0.9 + 0.2 * std::cos(k * x + k * y);
  };
  const double T = 2;
  std::vector<std::vector<std::vector<double>>> sol;
  std::vector<double> dts;
  for (int r = 0; r < 6; ++r) {
    const double dt = 0.025 / (1 << r);
    ps.dt = dt;
    auto p = make_problem(PETSC_COMM_WORLD, ps);
    p->run(static_cast<int>(std::lround(T / dt)), dt);
    sol.push_back({gather_all(*p->grid, p->u[0]), gather_all(*p->grid, p->u[1])});
    dts.push_back(dt);
  }
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  double order = 0;
  if (rank == 0) {
    std::vector<double> diffs, hs;
    for (size_t r = 0; r + 1 < sol.size(); ++r) {
      double d = 0;
      for (int s = 0; s < 2; ++s)
        for (size_t c = 0; c < sol[r][s].size(); ++c)
          d = std::max(d, std::abs(sol[r][s][c] - sol[r + 1][s][c]));
      diffs.push_back(d);
      hs.push_back(dts[r]);
      printf("  Schnakenberg, |u(dt=%g) - u(dt=%g)| = %.4e\n", dts[r], dts[r + 1], d);
    }
    order = fitted_order(hs, diffs);
    printf("  Schnakenberg successive differences: fitted temporal order %.4f\n", order);
  }
  MPI_Bcast(&order, 1, MPI_DOUBLE, 0, PETSC_COMM_WORLD);
  EXPECT_NEAR(order, 2.0, 0.1);
}

namespace {

std::vector<std::vector<double>> run_gathered(MPI_Comm comm, const ProblemSpec& ps, int steps) {
  auto p = make_problem(comm, ps);
  p->run(steps, ps.dt);
  std::vector<std::vector<double>> out;
  for (auto& v : p->u)
    out.push_back(gather_all(*p->grid, v));
  return out;
}

// Runs `ps` on PETSC_COMM_WORLD and on PETSC_COMM_SELF; true when they agree to 1e-10 relative.
bool world_and_self_agree(const ProblemSpec& ps, int steps) {
  const auto world = run_gathered(PETSC_COMM_WORLD, ps, steps);
  const auto self = run_gathered(PETSC_COMM_SELF, ps, steps);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  bool ok = true;
  if (rank == 0) {
    double rel = 0, change = 0;
    for (size_t s = 0; s < world.size(); ++s) {
      double num = 0, den = 0, mn = world[s][0], mx = world[s][0];
      for (size_t c = 0; c < world[s].size(); ++c) {
        num = std::max(num, std::abs(world[s][c] - self[s][c]));
        den = std::max(den, std::abs(self[s][c]));
        mn = std::min(mn, world[s][c]), mx = std::max(mx, world[s][c]);
      }
      rel = std::max(rel, num / den);
      change = std::max(change, mx - mn);
    }
    printf("  %d-D, %d ranks vs 1 rank: max relative difference %.3e\n", ps.dim, comm_size(), rel);
    EXPECT_LT(rel, 1e-10);
    EXPECT_GT(change, 1e-3); // the run evolved
    ok = rel < 1e-10 && change > 1e-3;
  }
  return all_ranks(ok);
}

ProblemSpec equivalence_spec() {
  ProblemSpec ps;
  ps.D = {1.0, 20.0};
  ps.dirichlet = {1.0, 0.9};
  ps.param_field = [](int q, double x, double y, double z) {
    const double def[3] = {0.1, 0.9, 1.0};
    return def[q] * (1 + 0.05 * std::sin(0.3 * x) * std::cos(0.2 * y + 0.1 * z));
  };
  ps.init = [](int s, double, double, double, PetscInt i, PetscInt j, PetscInt k) {
    // Rank-independent pseudo-random start about the steady state (1, 0.9).
    const double r = std::sin(12.9898 * i + 78.233 * j + 53.531 * k + 37.719 * s) * 43758.5453;
    return (s == 0 ? 1.0 : 0.9) + 0.05 * (r - std::floor(r) - 0.5);
  };
  ps.dt = 0.5;
  return ps;
}

} // namespace

TEST(TsIntegrator, WorldAndSelfAgree2D) {
  ProblemSpec ps = equivalence_spec();
  ps.nx = 40, ps.ny = 30;
  ps.Lx = 40, ps.Ly = 30;
  ps.bcx = Boundary::Neumann;
  ps.bcy = Boundary::Dirichlet;
  EXPECT_TRUE(world_and_self_agree(ps, 20));
}

TEST(TsIntegrator, WorldAndSelfAgree3D) {
  ProblemSpec ps = equivalence_spec();
  ps.dim = 3;
  ps.nx = 12, ps.ny = 10, ps.nz = 9;
  ps.Lx = 12, ps.Ly = 10, ps.Lz = 9;
  ps.bcx = Boundary::Periodic;
  ps.bcy = Boundary::Neumann;
  ps.bcz = Boundary::Dirichlet;
  EXPECT_TRUE(world_and_self_agree(ps, 10));
}

TEST(TsIntegrator, DirichletLinearSteadyState) {
  // Pure diffusion with u = 1 at x = 0 and u = 3 at x = Lx: steady state 1 + 2 x / Lx.
  ProblemSpec ps;
  ps.nx = 16, ps.ny = 6;
  ps.Lx = 16, ps.Ly = 6;
  ps.bcx = Boundary::Dirichlet;
  ps.model = "turing";
  ps.params = {12, 16, 0};
  ps.D = {1.0, 1.0};
  ps.init = [](int, double, double, double, PetscInt, PetscInt, PetscInt) { return 0.0; };
  ps.dt = 20;
  // Different values on the two faces need per-face data: set the faces by hand below.
  ps.dirichlet = {1.0, 1.0};
  set_options({});
  auto p = make_problem(PETSC_COMM_WORLD, ps);
  // Rebuild the Laplacian and integrator with face values 1 (x = 0) and 3 (x = Lx).
  p->ts.reset();
  for (auto& f : p->dirichlet)
    std::fill(f.face[1].begin(), f.face[1].end(), 3.0);
  p->build_matrices(ps.D, &p->dirichlet);
  p->build_ts({-kInf, -kInf}, ps.dt);
  p->run(100, ps.dt);
  for (int s = 0; s < 2; ++s)
    EXPECT_LT(p->max_error(s, [](double x, double) { return 1 + 2 * x / 16; }), 1e-8);
}

TEST(TsIntegrator, AdaptiveTakesSeveralAccurateInternalSteps) {
  DiffusionMode m;
  auto p = make_problem(
      PETSC_COMM_WORLD,
      m.spec(m.T, {{"ts_adapt_type", "basic"}, {"ts_rtol", "1e-7"}, {"ts_atol", "1e-7"}}));
  ASSERT_TRUE(p->ts->adaptive());
  p->run(1, m.T); // one call over the whole interval
  const double err = m.error(*p);
  PetscPrintf(PETSC_COMM_WORLD, "  adaptive: %d internal steps, %d rejected, error %.3e\n",
              static_cast<int>(p->ts->total_steps()), static_cast<int>(p->ts->total_rejected()),
              err);
  EXPECT_GT(p->ts->total_steps(), 3);
  EXPECT_LT(err, 1e-5);
}

TEST(TsIntegrator, FailedLinearSolveIsUserError) {
  DiffusionMode m;
  auto p = make_problem(PETSC_COMM_WORLD, m.spec(0.1, {{"ksp_max_it", "1"}}));
  std::string msg;
  try {
    p->run(1, 0.1);
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("diverged at step 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("DIVERGED_ITS"), std::string::npos) << msg;
  EXPECT_TRUE(all_ranks(!msg.empty()));
  PetscPrintf(PETSC_COMM_WORLD, "  message: %s\n", msg.c_str());
}

TEST(TsIntegrator, OtherSchemesFromOptions) {
  DiffusionMode dm;
  Manufactured mm;
  // A third-order ARKIMEX scheme.
  const double o3 = measure_order(
      "diffusion mode, -ts_arkimex_type 3",
      [&](double dt) {
        return dm.spec(dt, {{"ts_arkimex_type", "3"}});
      },
      [&](Problem& p) { return dm.error(p); }, dm.T, 0.1, 4);
  EXPECT_NEAR(o3, 3.0, 0.15);
  // BDF2 keeps its history across step() calls (a restart every call would make it BDF1).
  const double obdf = measure_order(
      "Schnakenberg MMS, -ts_type bdf",
      [&](double dt) {
        return mm.spec(dt, {{"ts_type", "bdf"}, {"ts_bdf_order", "2"}});
      },
      [&](Problem& p) { return mm.error(p); }, mm.T, 0.05, 4);
  EXPECT_NEAR(obdf, 2.0, 0.1);
  // Crank-Nicolson is fully implicit: the default SNES becomes Newton (ksponly would leave
  // the reaction linearised, first order).
  const double ocn = measure_order(
      "Schnakenberg MMS, -ts_type cn",
      [&](double dt) {
        return mm.spec(dt, {{"ts_type", "cn"}});
      },
      [&](Problem& p) { return mm.error(p); }, mm.T, 0.05, 4);
  EXPECT_NEAR(ocn, 2.0, 0.1);
  // Explicit TS types cannot take the implicit part: a UserError at construction.
  std::string msg;
  try {
    make_problem(PETSC_COMM_WORLD, dm.spec(0.1, {{"ts_type", "rk"}}));
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("-ts_type rk"), std::string::npos) << msg;
}

TEST(TsIntegrator, FloorClampsAndRestarts) {
  // A floor above part of the solution: every step clamps, so every step restarts the TS.
  ProblemSpec ps;
  ps.nx = ps.ny = 16;
  ps.Lx = ps.Ly = 16;
  ps.D = {1.0, 20.0};
  ps.floor = {0.97, -kInf};
  ps.init = [](int s, double x, double y, double, PetscInt, PetscInt, PetscInt) {
    const double k = 2 * M_PI / 16;
    return s == 0 ? 1 + 0.3 * std::sin(k * x) * std::cos(2 * k * y) : 0.9;
  };
  ps.dt = 0.1;
  auto p = make_problem(PETSC_COMM_WORLD, ps);
  p->run(20, ps.dt);
  EXPECT_EQ(p->ts->total_steps(), 20);
  double mn = kInf;
  const Box& ob = p->grid->owned();
  const PetscScalar* a;
  VecGetArrayRead(p->u[0], &a);
  for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
    for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
      mn = std::min(mn, a[p->grid->local_index(i, j, 0)]);
  VecRestoreArrayRead(p->u[0], &a);
  MPI_Allreduce(MPI_IN_PLACE, &mn, 1, MPI_DOUBLE, MPI_MIN, PETSC_COMM_WORLD);
  EXPECT_EQ(mn, 0.97);
}

TEST(TsIntegrator, SourceErrorInCallbackIsRethrown) {
  // The source is NaN after t = 0.05: the RHS callback's UserError (from the collective range
  // check of SourceTerms) must come out of step() on every rank, not as a PETSc error.
  Manufactured m;
  ProblemSpec ps = m.spec(0.1);
  ps.options = {{"source_u", "sqrt(0.05 - t)"}};
  auto p = make_problem(PETSC_COMM_WORLD, ps);
  std::string msg;
  try {
    p->run(1, 0.1);
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("source_u"), std::string::npos) << msg;
  EXPECT_TRUE(all_ranks(!msg.empty()));
  EXPECT_NE(msg.find("step 1"), std::string::npos) << msg;
  PetscPrintf(PETSC_COMM_WORLD, "  message: %s\n", msg.c_str());
}

TEST(TsIntegrator, ExplicitDiffusionRk4FourthOrder) {
  // -ts_diffusion explicit: every term in the right-hand side, read through DMGlobalToLocal;
  // classical RK4 on the pure-diffusion mode converges with order 4 to the discrete solution.
  DiffusionMode m;
  const double order = measure_order(
      "diffusion mode, explicit diffusion, -ts_type rk -ts_rk_type 4",
      [&](double dt) {
        ProblemSpec ps = m.spec(dt, {{"ts_type", "rk"}, {"ts_rk_type", "4"}});
        ps.implicit_diffusion = false;
        return ps;
      },
      [&](Problem& p) { return m.error(p); }, m.T, 0.05, 4);
  EXPECT_NEAR(order, 4.0, 0.15);
}

TEST(TsIntegrator, ExplicitDiffusionRefusesImplicitTypes) {
  DiffusionMode m;
  ProblemSpec ps = m.spec(0.01, {{"ts_type", "bdf"}});
  ps.implicit_diffusion = false;
  std::string msg;
  try {
    make_problem(PETSC_COMM_WORLD, ps);
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("-ts_type bdf"), std::string::npos) << msg;
}

TEST(TsIntegrator, BadTypeNameIsOneLineUserError) {
  DiffusionMode m;
  std::string msg;
  try {
    make_problem(PETSC_COMM_WORLD, m.spec(0.1, {{"ts_type", "nosuch"}}));
  } catch (const UserError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("nosuch"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_TRUE(all_ranks(!msg.empty()));
}

namespace {

// A run with a rotated, varying tensor (box stencil: ghost corners), zero-flux walls in x and
// periodic y, advanced by `integrator` options; returns species a gathered on rank 0.
std::vector<double> tensor_run(const OptionList& integrator, int steps) {
  OptionList opts = {{"model", "turing"},
                     {"grid_n", "24,20"},
                     {"grid_bc", "neumann,periodic"},
                     {"diffusion", "tensor"},
                     {"tensor_theta", "atan2(y - 10, x - 12)"},
                     {"tensor_l1", "0.3 + 0.01*x"},
                     {"tensor_l2", "0.1"},
                     {"init_a", "4 +- 20%"},
                     {"init_b", "4 +- 20%"},
                     {"dt", "0.2"},
                     {"summary", "false"}};
  opts.insert(opts.end(), integrator.begin(), integrator.end());
  auto sim = make_sim(PETSC_COMM_WORLD, opts);
  for (int n = 0; n < steps; ++n)
    sim->step();
  return gather_all(sim->grid(), sim->state()[0]);
}

} // namespace

TEST(TsIntegrator, ExplicitDiffusionEulerMatchesExplicitIntegrator) {
  // TS forward Euler with the tensor diffusion in the right-hand side (ghosts from
  // DMGlobalToLocal, walls filled per component of the interlaced local Vec) against the
  // explicit integrator's general path: the same scheme, summed in another order.
  const auto a = tensor_run({{"integrator", "explicit"}}, 30);
  const auto b =
      tensor_run({{"integrator", "ts"}, {"ts_diffusion", "explicit"}, {"ts_type", "euler"}}, 30);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  double diff = 0, scale = 0;
  if (rank == 0) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t c = 0; c < a.size(); ++c) {
      diff = std::max(diff, std::abs(a[c] - b[c]));
      scale = std::max(scale, std::abs(a[c]));
    }
    PetscPrintf(PETSC_COMM_SELF, "  explicit vs TS euler (explicit diffusion): max diff %.3e\n",
                diff);
  }
  EXPECT_TRUE(all_ranks(diff <= 1e-12 * scale));
}
