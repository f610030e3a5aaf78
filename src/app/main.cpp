// morphogen: MPI-distributed reaction-diffusion (Turing pattern) solver.
//
//   morphogen [DECK.yaml] [-option value ...]
//
// Loads the deck (or the embedded default, Sanderson Fig. 1) into PETSc's options database,
// overrides it with the command line, validates every option (unknown options fail with a
// "did you mean"), writes options_used.yaml and runs. Exit codes: 0 success, 1 bad input or a
// diverged run (one-line message), 2 an internal PETSc error (PETSc prints its trace).
#include "app/deck.hpp"
#include "app/run_loop.hpp"
#include "app/simulation.hpp"
#include "core/collective_error.hpp"
#include "core/user_error.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <vector>

using namespace morphogen;

namespace {

void print_models(MPI_Comm comm) {
  PetscPrintf(comm, "\nModels (-model NAME):\n");
  for (const auto& m : model_registry()) {
    PetscPrintf(comm, "  %-18s %s (%s)\n", m.name, m.doc, m.reference);
    for (int s = 0; s < m.nspecies; ++s)
      PetscPrintf(comm, "      species %-6s D %-10s init %-10s %s\n", m.species[s].name,
                  format_double(m.species[s].D).c_str(), format_double(m.species[s].init).c_str(),
                  m.species[s].doc);
    for (int q = 0; q < m.nparams; ++q)
      PetscPrintf(comm, "      param   %-6s default %-10s range [%s, %s]  %s\n", m.params[q].name,
                  format_double(m.params[q].def).c_str(), format_double(m.params[q].lo).c_str(),
                  format_double(m.params[q].hi).c_str(), m.params[q].doc);
  }
}

void prepare_output(MPI_Comm comm, const Options& opt, const Simulation& sim) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string err;
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::create_directories(sim.output().dir, ec);
    if (ec) {
      err = "-output_dir " + sim.output().dir + ": cannot create directory (" + ec.message() + ")";
    } else {
      const std::string path = sim.output().dir + "/options_used.yaml";
      std::ofstream f(path);
      f << opt.to_yaml("# Options of this run, resolved (morphogen " MORPHOGEN_VERSION
                       "). Rerun with: morphogen " +
                       path + "\n");
      if (!f) err = "-output_dir " + sim.output().dir + ": cannot write " + path;
    }
  }
  throw_if_any(comm, err);
}

void print_header(MPI_Comm comm, const Simulation& sim, int level, int levels) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const auto& g = sim.grid().spec();
  if (levels > 1) PetscPrintf(comm, "level %d/%d: ", level + 1, levels);
  PetscPrintf(comm, "morphogen %s: model %s, grid %lld", MORPHOGEN_VERSION, sim.model().name,
              static_cast<long long>(g.n[0]));
  for (int d = 1; d < g.dim; ++d)
    PetscPrintf(comm, "x%lld", static_cast<long long>(g.n[d]));
  PetscPrintf(comm, " (%s", boundary_name(g.bc[0]));
  for (int d = 1; d < g.dim; ++d)
    PetscPrintf(comm, ",%s", boundary_name(g.bc[d]));
  PetscPrintf(comm, "), %s stencil, dt %s (explicit bound %s), %lld steps, %d rank%s -> %s/\n",
              sim.stencil().name.c_str(), format_double(sim.dt()).c_str(),
              format_double(sim.stable_dt()).c_str(), static_cast<long long>(sim.steps()), size,
              size == 1 ? "" : "s", sim.output().dir.c_str());
}

int run(int* argc, char*** argv) {
  MPI_Comm comm = PETSC_COMM_WORLD;
  const std::string base_dir = load_deck(argc, argv);
  Options opt(comm);
  if (opt.help_requested())
    PetscPrintf(comm, "morphogen %s options (-name <current value>: help):\n", MORPHOGEN_VERSION);
  // Coarse-to-fine grid sequencing (Witkin-Kass 5.2, Lawlor): levels 1..L-1 run on grids
  // coarsened by 2^(L-1-l) for -sequence_steps steps each, the last on -grid_n for -steps.
  const int levels = static_cast<int>(
      opt.integer("sequence_levels", 1, 1, 8,
                  "coarse-to-fine grid sequencing: number of levels, each twice as fine as the "
                  "previous; the last is -grid_n"));
  std::vector<PetscInt> level_steps;
  if (levels > 1)
    for (const auto& v :
         opt.list("sequence_steps", {}, static_cast<size_t>(levels - 1),
                  static_cast<size_t>(levels - 1), "steps on each coarse level, coarsest first")) {
      const PetscInt n = Options::parse_int("sequence_steps", v);
      if (n < 0) throw UserError("-sequence_steps " + v + ": must be >= 0");
      level_steps.push_back(n);
    }
  std::unique_ptr<Simulation> prev;
  for (int l = 0; l < levels; ++l) {
    auto sim =
        std::make_unique<Simulation>(comm, opt, base_dir, SequenceLevel{l, levels, prev.get()});
    if (l == 0) {
      if (opt.help_requested()) {
        print_models(comm);
        return 0;
      }
      opt.check_unused();
      prepare_output(comm, opt, *sim);
    }
    if (l + 1 < levels) sim->set_steps(level_steps[l]);
    print_header(comm, *sim, l, levels);
    run_loop(*sim);
    prev = std::move(sim);
  }
  PetscPrintf(comm, "done: images in %s/ (*_final.png), options in %s/options_used.yaml\n",
              prev->output().dir.c_str(), prev->output().dir.c_str());
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  PetscCall(PetscInitialize(&argc, &argv, nullptr,
                            "morphogen [DECK.yaml] [-option value ...]; -help lists options\n"));
  int rc = 0;
  try {
    rc = run(&argc, &argv);
  } catch (const UserError& e) {
    PetscFPrintf(PETSC_COMM_WORLD, PETSC_STDERR, "morphogen: error: %s\n", e.what());
    rc = 1;
  } catch (const PetscFailure&) {
    // PETSc printed its trace; the failure may be on this rank only, so abort the job rather
    // than wait for the other ranks in PetscFinalize.
    MPI_Abort(PETSC_COMM_WORLD, 2);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "morphogen: internal error: %s\n", e.what());
    MPI_Abort(PETSC_COMM_WORLD, 2);
  }
  // Unused-option warnings are ours (check_unused); keep PETSc quiet about them at exit.
  PetscCall(PetscOptionsSetValue(nullptr, "-options_left", "0"));
  PetscCall(PetscFinalize());
  return rc;
}
