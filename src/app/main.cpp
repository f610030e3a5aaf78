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

int run(int* argc, char*** argv) {
  MPI_Comm comm = PETSC_COMM_WORLD;
  const std::string base_dir = load_deck(argc, argv);
  Options opt(comm);
  if (opt.help_requested())
    PetscPrintf(comm, "morphogen %s options (-name <current value>: help):\n", MORPHOGEN_VERSION);
  Simulation sim(comm, opt, base_dir);
  if (opt.help_requested()) {
    print_models(comm);
    return 0;
  }
  opt.check_unused();
  int size = 1;
  MPI_Comm_size(comm, &size);
  const auto& g = sim.grid().spec();
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
  prepare_output(comm, opt, sim);
  run_loop(sim);
  PetscPrintf(comm, "done: images in %s/ (*_final.png), options in %s/options_used.yaml\n",
              sim.output().dir.c_str(), sim.output().dir.c_str());
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
