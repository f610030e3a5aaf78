// morphogen-bench: explicit Gray-Scott cell-updates per second at 1024^2 (2-D) and 128^3 (3-D;
// -bench_3d_n 256 for out of cache) against a STREAM triad measured in the same process, printed
// as the fraction of the memory bandwidth roofline (32 bytes per 2-species cell-update in double:
// read u, v; write u, v).
// Also times the halo-only update used by the integrator against PETSc's full
// DMGlobalToLocal copy, and the general explicit path (diffusion tensor, diffusion map) with its
// own bytes per update and its ratio to the fused path, and Gray-Scott written as a custom model
// (-model custom: muParser expressions, evaluated a row at a time) against the compiled
// gray_scott with the same settings. First (-bench_implicit, issue 13 part 1): the split
// integrator's per-cell reaction solve in ns per cell (target <= 10), a split step against an
// explicit step on the same grid and ranks (target <= 10x) and the Brusselator deck to t = 125
// explicit vs split (target >= 4x faster, same pattern). Runs on any number of ranks (aggregate
// figures). Before all that (-bench_output_n, issue 13 parts 3-4, bench/bench_output.hpp): the
// setup ns per cell, the PNG time and the peak memory per cell at 4096^2. Last line:
// Then (-bench_fuse_steps, bench/bench_fused.hpp): the row kernel alone with its rows in cache
// and the bounds it sets, the fused wavefront over its ring alone (bench/bench_kernel_rate.hpp),
// fused explicit steps (temporal blocking)
// at 2048^2 and 4096^2 against one step per pass and the roofline. First line: the machine
// (bench/bench_machine.hpp: CPU, caches, nodes; the out-of-cache lines end with the grid's
// state per node against its L3). Last line:
//   roofline_fraction=<2-D fraction>
#include "app/pattern_summary.hpp"
#include "app/simulation.hpp"
#include "bench/bench_access_pattern.hpp"
#include "bench/bench_fluids.hpp"
#include "bench/bench_fused.hpp"
#include "bench/bench_kernel_rate.hpp"
#include "bench/bench_machine.hpp"
#include "bench/bench_output.hpp"
#include "bench/bench_scaling.hpp"
#include "bench/bench_scoped_options.hpp"
#include "bench/bench_timing.hpp"
#include "core/user_error.hpp"
#include "integrators/model_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

using namespace morphogen;

namespace {

// STREAM triad a = b + s c over n doubles per rank, best of `reps`; aggregate bytes/s.
double stream_triad(MPI_Comm comm, size_t n, int reps) {
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  double best = 1e30;
  for (int r = 0; r < reps; ++r) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    const double s = 3.0 + r;
    double* __restrict__ pa = a.data();
    const double* __restrict__ pb = b.data();
    const double* __restrict__ pc = c.data();
    for (size_t i = 0; i < n; ++i)
      pa[i] = pb[i] + s * pc[i];
    double dt = MPI_Wtime() - t0, dtmax = 0;
    MPI_Allreduce(&dt, &dtmax, 1, MPI_DOUBLE, MPI_MAX, comm);
    best = std::min(best, dtmax);
  }
  volatile double sink = a[n / 2];
  (void)sink;
  int size = 1;
  MPI_Comm_size(comm, &size);
  return 24.0 * static_cast<double>(n) * size / best;
}

struct Result {
  double cups = 0, halo_s = 0, g2l_s = 0;
  ProbeRun probe; // cups again, with the stencil and species the halo moves
};

// Diffusion options of the general-path cases (cleared before each case).
const char* const kDiffusionKeys[] = {
    "-diffusion", "-tensor_theta", "-tensor_l1", "-tensor_l2", "-D_a",      "-D_b",    "-species",
    "-rate_a",    "-rate_b",       "-params_F",  "-params_k",  "-params_s", "-stencil"};

Result bench_explicit(MPI_Comm comm, Options& opt, const std::string& n, int steps,
                      const std::vector<std::pair<std::string, std::string>>& extra = {},
                      const char* model = "gray_scott") {
  for (const char* k : kDiffusionKeys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  for (auto& [k, v] : extra)
    MG_PETSC(PetscOptionsSetValue(nullptr, k.c_str(), v.c_str()));
  const std::pair<const char*, const char*> opts[] = {
      {"-model", model},
      {"-grid_n", n.c_str()},
      {"-grid_L", "2.5"},
      {"-init_a", "0.25*square(1.25,1.25,0.1) +- 1%"},
      {"-init_b", "1 - 0.5*square(1.25,1.25,0.1)"}};
  for (auto& [k, v] : opts)
    MG_PETSC(PetscOptionsSetValue(nullptr, k, v));
  apply_integrator_options();
  Simulation sim(comm, opt, "");
  for (int i = 0; i < 5; ++i)
    sim.step(); // warm up
  Result r;
  r.cups =
      static_cast<double>(sim.grid().global_cells()) / best_seconds_per_step(comm, sim, steps, 3);
  r.probe = {r.cups, sim.grid().spec().stencil_width, sim.grid().spec().box_stencil,
             static_cast<int>(sim.species().size())};
  // Halo-only update vs. PETSc's global-to-local copy, per species per step.
  const int reps = 50;
  MPI_Barrier(comm);
  double t0 = MPI_Wtime();
  for (int i = 0; i < reps; ++i)
    sim.refresh_ghosts();
  r.halo_s = (MPI_Wtime() - t0) / reps / 2;
  VecH g = sim.grid().create_global();
  MPI_Barrier(comm);
  t0 = MPI_Wtime();
  for (int i = 0; i < reps; ++i) {
    MG_PETSC(DMGlobalToLocalBegin(sim.grid().dm(), g, INSERT_VALUES, sim.state()[0]));
    MG_PETSC(DMGlobalToLocalEnd(sim.grid().dm(), g, INSERT_VALUES, sim.state()[0]));
  }
  r.g2l_s = (MPI_Wtime() - t0) / reps;
  return r;
}

// One split step (Strang: trapezoidal implicit reaction, Crank-Nicolson diffusion) of Turing
// Fig. 1 at 1024^2 with dt = 10x the explicit bound, for one diffusion solver: the default (auto:
// the exact transform on this periodic grid) or KSP with one preconditioner.
struct SplitResult {
  double seconds_per_step = 0, its_per_solve = 0;
};

SplitResult bench_split(MPI_Comm comm, Options& opt,
                        const std::vector<std::pair<std::string, std::string>>& pc, int steps) {
  static const char* const keys[] = {"-diffusion_solver", "-diffusion_pc_type",
                                     "-diffusion_pc_mg_levels", "-diffusion_pc_mg_galerkin",
                                     "-diffusion_pc_hypre_type"};
  for (const char* k : keys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  const std::pair<const char*, const char*> base[] = {{"-model", "turing"},
                                                      {"-grid_n", "1024,1024"},
                                                      {"-grid_L", "1024"},
                                                      {"-init_a", "4"},
                                                      {"-init_b", "4"},
                                                      {"-params_alpha", "12 +- 0.1% gauss"},
                                                      {"-params_beta", "16 +- 0.1% gauss"},
                                                      {"-integrator", "split"},
                                                      {"-dt", "10"}};
  for (auto& [k, v] : base)
    MG_PETSC(PetscOptionsSetValue(nullptr, k, v));
  for (auto& [k, v] : pc)
    MG_PETSC(PetscOptionsSetValue(nullptr, k.c_str(), v.c_str()));
  apply_integrator_options();
  Simulation sim(comm, opt, "");
  sim.step(); // assembles the matrices and sets up the preconditioners
  const PetscInt its0 = sim.diffusion_solver()->total_iterations();
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  for (int i = 0; i < steps; ++i)
    sim.step();
  MPI_Barrier(comm);
  SplitResult r;
  r.seconds_per_step = (MPI_Wtime() - t0) / steps;
  r.its_per_solve =
      static_cast<double>(sim.diffusion_solver()->total_iterations() - its0) / (2.0 * steps);
  return r;
}

// ---------------------------------------------------------------------------------------------
// Implicit steps against explicit ones (issue 13 part 1), on the Brusselator deck
// (input/brusselator.yaml: periodic, h = 1.5, D 49.4 / 117.6, explicit dt 0.0025, split dt 0.1).

using OptionPairs = std::vector<std::pair<std::string, std::string>>;

void set_case(const OptionPairs& opts) {
  static const char* const keys[] = {"-model",
                                     "-grid_n",
                                     "-grid_L",
                                     "-grid_bc",
                                     "-init_a",
                                     "-init_b",
                                     "-params_alpha",
                                     "-params_beta",
                                     "-params_s",
                                     "-integrator",
                                     "-dt",
                                     "-D_a",
                                     "-D_b",
                                     "-diffusion",
                                     "-diffusion_solver",
                                     "-diffusion_slow_axis",
                                     "-split_reaction",
                                     "-split_fuse_reaction",
                                     "-ts_adapt_type",
                                     "-diffusion_pc_type",
                                     "-diffusion_pc_mg_levels",
                                     "-diffusion_pc_mg_galerkin",
                                     "-diffusion_pc_hypre_type",
                                     "-params_F",
                                     "-params_k",
                                     "-species",
                                     "-rate_a",
                                     "-rate_b",
                                     "-tensor_theta",
                                     "-tensor_l1",
                                     "-tensor_l2"};
  for (const char* k : keys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  for (auto& [k, v] : opts)
    MG_PETSC(PetscOptionsSetValue(nullptr, k.c_str(), v.c_str()));
}

OptionPairs brusselator_deck(int n, const std::string& integrator, const std::string& dt,
                             const std::string& solver = "auto",
                             const std::string& reaction = "trapezoidal") {
  OptionPairs o = {{"-model", "brusselator"},
                   {"-grid_n", std::to_string(n) + "," + std::to_string(n)},
                   {"-grid_L", std::to_string(1.5 * n)},
                   {"-grid_bc", "periodic"},
                   {"-params_alpha", "3"},
                   {"-params_beta", "9"},
                   {"-params_s", "1"},
                   {"-D_a", "49.4"},
                   {"-D_b", "117.6"},
                   {"-init_a", "3 +- 1%"},
                   {"-init_b", "3 +- 1%"},
                   {"-integrator", integrator},
                   {"-dt", dt}};
  if (integrator == "split") {
    o.push_back({"-diffusion_solver", solver});
    o.push_back({"-split_reaction", reaction});
  }
  if (integrator == "ts") o.push_back({"-ts_adapt_type", "basic"}); // dt: the first step only
  return o;
}

// The run of the case `o` (its options set, then read by Simulation), after 2 warm-up steps.
std::unique_ptr<Simulation> warm_run(MPI_Comm comm, Options& opt, const OptionPairs& o) {
  set_case(o);
  apply_integrator_options();
  auto sim = std::make_unique<Simulation>(comm, opt, "");
  sim->step();
  sim->step();
  return sim;
}

// The per-cell reaction substep alone: nanoseconds per cell of the Strang half-step (dt 0.05,
// trapezoidal, tol 1e-12) for Brusselator cells spread +-30 % around the steady state (a formed
// pattern's range), the per-cell solver (reaction_row) against the lockstep one.
void bench_reaction_kernel(MPI_Comm comm) {
  using M = models::Brusselator;
  const int n = 256, rows = 256;
  std::vector<double> a(n * rows), b(n * rows), oa(n), ob(n);
  for (int i = 0; i < n * rows; ++i) {
    a[i] = 3.0 * (1.0 + 0.3 * std::sin(0.37 * i));
    b[i] = 3.0 * (1.0 - 0.3 * std::sin(0.37 * i + 0.5));
  }
  const double p[3] = {3, 9, 1}, floor[2] = {-HUGE_VAL, -HUGE_VAL};
  double* out[2] = {oa.data(), ob.data()};
  // Wall time and this thread's CPU time (the latter ignores time descheduled on a shared host).
  auto cpu_now = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  double best_cpu = 1e30;
  // The lockstep row as the split integrator runs it: the model's reaction kernels (compiled
  // with FMA contraction, integrators/kernels/brusselator_reaction.cpp).
  const ReactionRowFn lockstep_row = model_kernels<M>().reaction_row[0];
  auto time = [&](bool lockstep, int* its, ReactionScheme scheme = ReactionScheme::Trapezoidal) {
    double best = 1e30;
    best_cpu = 1e30;
    for (int rep = 0; rep < 5; ++rep) {
      const double t0 = MPI_Wtime(), c0 = cpu_now();
      for (int r = 0; r < rows; ++r) {
        const double* in[2] = {a.data() + r * n, b.data() + r * n};
        CellSolve w{};
        const int bad = lockstep ? lockstep_row(scheme, n, in, nullptr, p, nullptr, nullptr, 0.05,
                                                1e-12, 20, floor, out, &w)
                                 : reaction_row<M, false>(scheme, n, in, nullptr, p, nullptr,
                                                          nullptr, 0.05, 1e-12, 20, floor, out, &w);
        if (bad >= 0) throw UserError("bench: reaction kernel failed");
        *its = std::max(*its, w.iterations);
      }
      best = std::min(best, MPI_Wtime() - t0);
      best_cpu = std::min(best_cpu, cpu_now() - c0);
    }
    return 1e9 * best / (n * rows);
  };
  int its_g = 0, its_l = 0;
  const double g = time(false, &its_g), l = time(true, &its_l);
  const double l_cpu = 1e9 * best_cpu / (n * rows);
  PetscPrintf(comm,
              "split_reaction_kernel model=brusselator scheme=trapezoidal dt=0.05 cells=%d "
              "per_cell_ns=%.1f lockstep_ns=%.1f lockstep_cpu_ns=%.1f speedup=%.1f "
              "newton_its_max=%d target_lockstep_ns<=10 %s\n",
              n * rows, g, l, l_cpu, g / l, its_l, l <= 10.0 ? "met" : "NOT met");
  // The explicit substeps (-split_reaction heun|rk4), per-cell path against the vectorised row.
  for (const ReactionScheme scheme : {ReactionScheme::Heun, ReactionScheme::Rk4}) {
    const double hg = time(false, &its_g, scheme), hl = time(true, &its_l, scheme);
    PetscPrintf(comm,
                "split_reaction_kernel model=brusselator scheme=%s dt=0.05 cells=%d "
                "per_cell_ns=%.1f row_ns=%.1f speedup=%.1f target<=10 %s\n",
                scheme == ReactionScheme::Heun ? "heun" : "rk4", n * rows, hg, hl, hg / hl,
                hl <= 10.0 ? "met" : "NOT met");
  }
}

// A split step (auto: the exact transform solve where it applies, and KSP) against an explicit
// step on the same grid and ranks, Brusselator deck settings at n^2. Each split case's blocks
// (`steps` steps; the fused cases one pass of `pass` steps) alternate with blocks of the explicit
// run (20 times as many steps), best of 5 each: the ratio of two bests taken in the same minutes.
void bench_split_vs_explicit(MPI_Comm comm, Options& opt, int n, int steps, int pass) {
  const int ex_steps = std::max(10, steps * 20), reps = 5;
  const std::unique_ptr<Simulation> ex =
      warm_run(comm, opt, brusselator_deck(n, "explicit", "0.0025"));
  const TimedBlock ex_block{[&] { ex->step(); },
                            [&] {
                              for (int i = 0; i < ex_steps; ++i)
                                ex->step();
                            },
                            ex_steps};
  auto compare = [&](const OptionPairs& o, bool fused, const std::string& label) {
    const std::unique_ptr<Simulation> sp = warm_run(comm, opt, o);
    const int k = fused ? static_cast<int>(std::min<PetscInt>(pass, sp->fuse_steps())) : steps;
    const TimedBlock block{[&] { sp->step(); },
                           [&] {
                             if (fused)
                               sp->advance(k);
                             else
                               for (int i = 0; i < k; ++i)
                                 sp->step();
                           },
                           k};
    const auto [e, t] = interleaved_best(comm, ex_block, block, reps);
    PetscPrintf(comm,
                "split_vs_explicit grid=%dx%d model=brusselator %s%s split_step_ms=%.3f "
                "explicit_step_ms=%.4f ratio=%.1f target_ratio<=10 %s\n",
                n, n, label.c_str(), fused ? (" fused_passes=" + std::to_string(k)).c_str() : "",
                1e3 * t, 1e3 * e, t / e, t / e <= 10.0 ? "met" : "NOT met");
  };
  for (const char* solver : {"auto", "ksp"})
    compare(brusselator_deck(n, "split", "0.1", solver), false,
            std::string("diffusion_solver=") + solver);
  compare(brusselator_deck(n, "split", "0.1", "auto", "rk4"), false,
          "diffusion_solver=auto split_reaction=rk4");
  // The fused cases; the last again with the full transform along the slowest axis (fft) beside
  // the default (auto: tridiagonal along it where it applies).
  for (const char* reaction : {"trapezoidal", "rk4", "rk4 fft"}) {
    const std::string r(reaction), scheme = r.substr(0, r.find(' '));
    const std::string slow = r.find("fft") != std::string::npos ? "fft" : "auto";
    OptionPairs fused = brusselator_deck(n, "split", "0.1", "auto", scheme);
    fused.push_back({"-split_fuse_reaction", "true"});
    fused.push_back({"-diffusion_slow_axis", slow});
    compare(fused, true,
            "diffusion_solver=auto diffusion_slow_axis=" + slow + " split_reaction=" + scheme);
  }
}

struct DeckRun {
  double seconds = 0, wavelength = 0;
  long spots = 0;
  std::string cls;
};

DeckRun run_deck(MPI_Comm comm, Options& opt, const OptionPairs& o, PetscInt steps) {
  set_case(o);
  apply_integrator_options();
  Simulation sim(comm, opt, "");
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  for (PetscInt i = 0; i < steps;) { // passes of fused steps where the case fuses them
    const PetscInt pass = std::min(sim.fuse_steps(), steps - i);
    sim.advance(pass);
    i += pass;
  }
  MPI_Barrier(comm);
  DeckRun r;
  r.seconds = MPI_Wtime() - t0;
  const nlohmann::json c = classify_species(sim, 0, nullptr);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    r.cls = c["class"].get<std::string>();
    const auto& m = c["metrics"];
    r.spots = std::max(m["high"]["spots"].get<long>(), m["low"]["spots"].get<long>());
    r.wavelength = m["wavelength"].is_number() ? m["wavelength"].get<double>() : 0.0;
  }
  return r;
}

// A split run of the deck against the explicit one: the same pattern (class, spot count +-5 %,
// wavelength +-2 %) and the speed-up.
struct DeckComparison {
  double dspots, dlam, speedup;
  bool same;
};
DeckComparison compare_deck_runs(const DeckRun& ex, const DeckRun& sp) {
  DeckComparison c;
  c.dspots = ex.spots ? std::fabs(double(sp.spots - ex.spots)) / ex.spots : 1.0;
  c.dlam = ex.wavelength > 0 ? std::fabs(sp.wavelength / ex.wavelength - 1.0) : 1.0;
  c.speedup = ex.seconds / sp.seconds;
  c.same = sp.cls == ex.cls && c.dspots <= 0.05 && c.dlam <= 0.02;
  return c;
}

void print_deck_run(MPI_Comm comm, double T, const char* tag, double dt, PetscInt steps,
                    const DeckRun& r) {
  PetscPrintf(comm,
              "brusselator_deck T=%g %s dt=%g steps=%d seconds=%.2f class=%s spots=%ld "
              "wavelength=%.2f\n",
              T, tag, dt, static_cast<int>(steps), r.seconds, r.cls.c_str(), r.spots, r.wavelength);
}

// input/brusselator.yaml to t = T: explicit dt 0.0025 against split dt `split_dt` (species a),
// plain, with fused Strang passes (-split_fuse_reaction), with the explicit Heun and RK4
// reaction substeps (-split_reaction heun|rk4: the deck's reaction is not stiff at dt 0.25, its
// diffusion is), and PETSc TS (ARKIMEX, adaptive steps) beside them.
void bench_brusselator_deck(MPI_Comm comm, Options& opt, double T, double split_dt, bool with_ts) {
  const PetscInt ex_steps = static_cast<PetscInt>(std::lround(T / 0.0025));
  const PetscInt sp_steps = static_cast<PetscInt>(std::lround(T / split_dt));
  char dt_text[32];
  std::snprintf(dt_text, sizeof dt_text, "%.17g", split_dt);
  const DeckRun ex = run_deck(comm, opt, brusselator_deck(256, "explicit", "0.0025"), ex_steps);
  print_deck_run(comm, T, "explicit", 0.0025, ex_steps, ex);
  struct Variant {
    const char *tag, *integrator, *reaction;
    bool fused;
  };
  std::vector<Variant> variants = {{"split", "split", "trapezoidal", false},
                                   {"split_fused", "split", "trapezoidal", true},
                                   {"split_heun", "split", "heun", false},
                                   {"split_rk4", "split", "rk4", false},
                                   {"split_rk4_fused", "split", "rk4", true}};
  if (with_ts) variants.push_back({"ts", "ts", "", false});
  for (const Variant& v : variants) {
    OptionPairs o = brusselator_deck(256, v.integrator, dt_text, "auto", v.reaction);
    if (v.fused) o.push_back({"-split_fuse_reaction", "true"});
    const DeckRun sp = run_deck(comm, opt, o, sp_steps);
    const char* tag = v.tag;
    print_deck_run(comm, T, tag, split_dt, sp_steps, sp);
    const DeckComparison c = compare_deck_runs(ex, sp);
    PetscPrintf(comm,
                "brusselator_deck speedup_%s_vs_explicit=%.2f target>=4 %s; same pattern "
                "(class, spots +-5%%, wavelength +-2%%): %s (spots %.1f%%, wavelength %.1f%%)\n",
                tag, c.speedup, c.speedup >= 4.0 ? "met" : "NOT met", c.same ? "yes" : "NO",
                100 * c.dspots, 100 * c.dlam);
  }
}

// -help: the bench's own options with their values and meaning (PETSc has printed its own
// above); nothing is timed.
void print_bench_help(MPI_Comm comm, const Options& opt) {
  PetscPrintf(comm,
              "\nmorphogen-bench %s: mpiexec -n P morphogen-bench [-option value ...]\n"
              "Sections, in order: setup/PNG/memory at -bench_output_n, fused steps, implicit vs "
              "explicit, explicit 2-D and 3-D, the general path, split preconditioners, strong "
              "scaling and the weak-scaling model (README, Performance). Any morphogen option "
              "also applies to every timed run; those of one integrator (-explicit_in_place, "
              "-explicit_vector_width, -explicit_fuse_tile, -explicit_fuse_steps, "
              "-explicit_prefetch; -ts_diffusion, "
              "-ts_diffusion_solver) only to that integrator's runs.\n"
              "Options (-name <value>: meaning):\n",
              MORPHOGEN_VERSION);
  for (const auto& r : opt.records())
    PetscPrintf(comm, "  -%s <%s>: %s\n", r.name.c_str(), r.value.c_str(), r.help.c_str());
}

int run(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  Options opt(comm);
  const PetscInt steps2 = opt.integer("bench_steps_2d", 200, 1, 1000000, "timed steps at 1024^2");
  const PetscInt steps3 = opt.integer("bench_steps_3d", 50, 1, 1000000, "timed steps in 3-D");
  const PetscInt n3 = opt.integer("bench_3d_n", 128, 8, 1024,
                                  "grid side of the 3-D cases (256: out of cache in 3-D)");
  const PetscInt steps_custom = opt.integer("bench_steps_custom", 20, 1, 1000000,
                                            "timed steps of the custom-model case at 1024^2");
  const bool with_split =
      opt.flag("bench_split", true, "also time the split integrator (CN + implicit reaction)");
  const PetscInt split_steps =
      opt.integer("bench_steps_split", 5, 1, 100000, "timed split steps per preconditioner");
  const PetscInt split_pass = opt.integer(
      "bench_split_pass", 20, 1, 100000,
      "steps per timed pass of the fused split_vs_explicit cases (a run fuses the steps between "
      "two observations of its state: NaN checks every 100 steps by default)");
  const PetscInt mb =
      opt.integer("bench_stream_mb", 256, 8, 65536, "STREAM array size per rank, MiB");
  const bool with_implicit =
      opt.flag("bench_implicit", true,
               "time the implicit path against explicit: reaction kernel, split step at 256^2 and "
               "1024^2, and the Brusselator deck (issue 13 part 1)");
  const double deck_T = opt.real("bench_brusselator_T", 125.0, 0.0, 1e6,
                                 "simulated time of the Brusselator deck comparison (0: skip)");
  const double deck_split_dt = opt.real("bench_brusselator_split_dt", 0.25, 1e-6, 100.0,
                                        "split step of the Brusselator deck comparison");
  const bool deck_ts =
      opt.flag("bench_brusselator_ts", true,
               "also run the Brusselator deck with -integrator ts (ARKIMEX, -ts_adapt_type basic)");
  const bool with_scaling = opt.flag(
      "bench_scaling", true,
      "strong scaling on this node (1 rank vs all) and the weak-scaling model for clusters");
  const bool only_implicit =
      opt.flag("bench_only_implicit", false, "only the implicit-vs-explicit section");
  const PetscInt output_n =
      opt.integer("bench_output_n", 4096, 0, 65536,
                  "grid side of the setup/PNG/peak-memory section, run first (0: skip)");
  const bool with_fluids = opt.flag(
      "bench_fluids", false,
      "time the stable-fluids solver + implicit ARD at 128^2..1024^2 (stable-ARD Table 1)");
  const PetscInt fluids_n =
      opt.integer("bench_fluids_n", 1024, 128, 1024, "largest grid side of -bench_fluids");
  const PetscInt fluids_steps =
      opt.integer("bench_fluids_steps", 5, 1, 100000, "timed steps per case of -bench_fluids");
  const bool only_fluids = opt.flag("bench_only_fluids", false, "only the fluids section");
  const bool only_fused =
      opt.flag("bench_only_fused", false, "only the fused-steps (temporal blocking) section");
  const PetscInt access_rows = opt.integer(
      "bench_access_rows", 2048, 0, 1 << 20,
      "rows of 4096 cells per rank and species of the access-pattern section (the memory side of "
      "an explicit step without its arithmetic; 2048: 64 MiB per species and rank; 0: skip)");
  const PetscInt access_3d_n = opt.integer(
      "bench_access_3d_n", 256, 0, 1024,
      "grid side of the access-pattern section's 3-D patterns, the 7-point sweep and the 9 rows "
      "of the 19/27-point stencils (side^3 cells over the ranks; 0: skip)");
  const bool only_access =
      opt.flag("bench_only_access_pattern", false, "only the access-pattern section");
  const FusedSettings fused = read_fused_settings(opt);
  const ScalingNetwork net = read_scaling_network(opt);
  if (opt.help_requested()) {
    print_bench_help(comm, opt);
    return 0;
  }
  opt.check_unused("bench_"); // a mistyped -bench_* option, before minutes of timings
  hold_integrator_options();  // -explicit_*, -ts_diffusion*: only for runs of their integrator
  const MachineInfo machine = print_machine(comm);
  if (with_fluids || only_fluids)
    bench_fluids(comm, opt, static_cast<int>(fluids_n), static_cast<int>(fluids_steps));
  if (only_fluids) return 0;
  if (output_n > 0 && !only_access) bench_output(comm, opt, static_cast<int>(output_n));
  const double bw = stream_triad(comm, static_cast<size_t>(mb) * 1024 * 1024 / 8, 10);
  const double roof = bw / 32.0;
  PetscPrintf(comm, "ranks=%d\nstream_triad_GBps=%.2f\nroofline_cell_updates_per_s=%.4e\n", size,
              bw / 1e9, roof);
  auto report = [&](const char* tag, const char* grid, const Result& r) {
    PetscPrintf(comm,
                "explicit_%s grid=%s model=gray_scott bytes_per_update=32 "
                "cell_updates_per_s=%.4e fraction=%.3f\n",
                tag, grid, r.cups, r.cups / roof);
    PetscPrintf(comm, "halo_%s halo_only_update_ms=%.4f dm_global_to_local_ms=%.4f\n", tag,
                1e3 * r.halo_s, 1e3 * r.g2l_s);
  };
  if (access_rows > 0 && !only_implicit)
    bench_access_pattern(comm, static_cast<int>(access_rows), roof);
  if (access_3d_n > 0 && !only_implicit)
    bench_access_pattern_3d(comm, static_cast<int>(access_3d_n), roof);
  if (only_access) return 0;
  if (!only_implicit) bench_fused(comm, opt, fused, roof, machine);
  if (only_fused) return 0;
  if (with_implicit) {
    bench_reaction_kernel(comm);
    bench_split_vs_explicit(comm, opt, 256, static_cast<int>(split_steps) * 4,
                            static_cast<int>(split_pass));
    opt.check_unused();
    bench_split_vs_explicit(comm, opt, 1024, static_cast<int>(split_steps),
                            static_cast<int>(split_pass));
    if (deck_T > 0) bench_brusselator_deck(comm, opt, deck_T, deck_split_dt, deck_ts);
  }
  if (only_implicit) return 0;
  set_case({});
  const Result r2 = bench_explicit(comm, opt, "1024,1024", static_cast<int>(steps2));
  opt.check_unused();
  report("2d", "1024x1024", r2);
  const std::string side3 = std::to_string(n3);
  const std::string grid3 = side3 + "," + side3 + "," + side3,
                    name3 = side3 + "x" + side3 + "x" + side3;
  const Result r3 = bench_explicit(comm, opt, grid3, static_cast<int>(steps3));
  report("3d", name3.c_str(), r3);
  // Issue 13 part 2: out of cache in 3-D (256^3) >= 0.85 of the roofline, box stencils too.
  auto target3 = [&](double cups) {
    return n3 < 256 ? std::string("target>=0.85 applies out of cache (-bench_3d_n 256)")
                    : std::string("target>=0.85 ") + (cups / roof >= 0.85 ? "met" : "NOT met");
  };
  const std::string in_l3 = l3_note(std::pow(static_cast<double>(n3), 3), machine);
  PetscPrintf(comm, "explicit_3d_target grid=%s fraction=%.3f %s%s\n", name3.c_str(),
              r3.cups / roof, target3(r3.cups).c_str(), in_l3.c_str());
  // The kernels alone and the bounds they set, on rows of the grid's side (at most 512 cells:
  // 2 species x 9 rows of 4 KiB, which at 512 already exceed a 48 KiB L1).
  for (const char* st : {"7pt", "19pt", "27pt"})
    print_row_kernel_bounds(comm, st, 3, roof, static_cast<int>(std::min<PetscInt>(n3, 512)));
  // The isotropic 3-D box stencils: the same bytes per update, 19 or 27 taps per species.
  for (const char* st : {"19pt", "27pt"}) {
    const Result rb =
        bench_explicit(comm, opt, grid3, static_cast<int>(steps3), {{"-stencil", st}});
    PetscPrintf(comm,
                "explicit_3d_%s grid=%s model=gray_scott bytes_per_update=32 "
                "cell_updates_per_s=%.4e fraction=%.3f vs_7pt=%.3f %s%s\n",
                st, name3.c_str(), rb.cups, rb.cups / roof, rb.cups / r3.cups,
                target3(rb.cups).c_str(), in_l3.c_str());
  }
  // The general path (diffusion from per-species operators, then the reaction, row by row):
  // a rotated tensor for both species (reads 3 dual-cell tensor components per species: 80
  // bytes per update) and a diffusion map for one species (40 bytes).
  const std::vector<std::tuple<const char*, int, std::vector<std::pair<std::string, std::string>>>>
      general = {{"2d_tensor",
                  80,
                  {{"-diffusion", "tensor"},
                   {"-tensor_theta", "0.5"},
                   {"-tensor_l1", "1.5"},
                   {"-tensor_l2", "0.5"}}},
                 {"2d_map", 40, {{"-D_a", "1e-5*(1 + 0.5*x/Lx)"}}}};
  for (const auto& [tag, bytes, extra] : general) {
    const Result rg = bench_explicit(comm, opt, "1024,1024", static_cast<int>(steps2), extra);
    PetscPrintf(comm,
                "explicit_%s grid=1024x1024 model=gray_scott bytes_per_update=%d "
                "cell_updates_per_s=%.4e fraction=%.3f vs_fused_2d=%.3f\n",
                tag, bytes, rg.cups, rg.cups / (bw / bytes), rg.cups / r2.cups);
  }
  // Gray-Scott as a custom model (muParser bytecode per row, general path) against the compiled
  // gray_scott (fused) with the same parameters, diffusion and grid: the cost of user-defined
  // kinetics. Fewer steps (it is ~10x slower).
  {
    const std::vector<std::pair<std::string, std::string>> custom = {
        {"-species", "a,b"},
        {"-rate_a", "s*(a^2*b - (F + k)*a)"},
        {"-rate_b", "s*(-a^2*b + F*(1 - b))"},
        {"-params_F", "0.04"},
        {"-params_k", "0.06"},
        {"-params_s", "1"},
        {"-D_a", "1e-5"},
        {"-D_b", "2e-5"}};
    const Result rc =
        bench_explicit(comm, opt, "1024,1024", static_cast<int>(steps_custom), custom, "custom");
    PetscPrintf(comm,
                "explicit_2d_custom grid=1024x1024 model=custom(gray_scott expressions) "
                "cell_updates_per_s=%.4e compiled_gray_scott_cell_updates_per_s=%.4e "
                "vs_compiled=%.3f\n",
                rc.cups, r2.cups, rc.cups / r2.cups);
  }
  for (const char* k : kDiffusionKeys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  if (with_split) {
    // The explicit step for comparison: same model and grid as the split runs.
    const double explicit_s = 1024.0 * 1024.0 / r2.cups;
    PetscPrintf(comm, "split_1024x1024 explicit_step_s=%.4f (Gray-Scott above)\n", explicit_s);
    const std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>>
        pcs = {{"auto", {}}, // what a run gets by default: here the exact transform, no KSP
               {"icc", {{"-diffusion_solver", "ksp"}}},
               {"mg",
                {{"-diffusion_pc_type", "mg"},
                 {"-diffusion_pc_mg_levels", "5"},
                 {"-diffusion_pc_mg_galerkin", "both"}}},
               {"hypre",
                {{"-diffusion_pc_type", "hypre"}, {"-diffusion_pc_hypre_type", "boomeramg"}}}};
    for (const auto& [name, pc] : pcs) {
      const SplitResult sr = bench_split(comm, opt, pc, static_cast<int>(split_steps));
      PetscPrintf(comm,
                  "split_1024x1024 pc=%s seconds_per_step=%.4f ksp_its_per_solve=%.1f "
                  "cost_vs_explicit_step=%.1f\n",
                  name.c_str(), sr.seconds_per_step, sr.its_per_solve,
                  sr.seconds_per_step / explicit_s);
    }
  }
  if (with_scaling) {
    const ScalingProbes probe = {
        [&](MPI_Comm c) { return stream_triad(c, static_cast<size_t>(mb) * 1024 * 1024 / 8, 10); },
        [&](MPI_Comm c, Options& o, const std::string& n) {
          set_case({});
          return bench_explicit(
                     c, o, n,
                     static_cast<int>(std::count(n.begin(), n.end(), ',') == 2 ? steps3 : steps2))
              .probe;
        }};
    bench_scaling(comm, opt, probe, net);
  }
  PetscPrintf(comm, "roofline_fraction=%.3f\n", r2.cups / roof);
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  int rc = 0;
  try {
    rc = run(PETSC_COMM_WORLD);
  } catch (const UserError& e) {
    PetscFPrintf(PETSC_COMM_WORLD, PETSC_STDERR, "morphogen-bench: error: %s\n", e.what());
    rc = 1;
  } catch (const PetscFailure&) {
    rc = 2;
  }
  PetscCall(PetscFinalize());
  return rc;
}
