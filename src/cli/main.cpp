// morphogen: MPI-distributed reaction-diffusion (Turing pattern) solver.
//
//   morphogen [DECK.yaml] [-option value ...]           (one run, app/run_main.hpp)
//   morphogen sweep DECK.yaml [-option value ...]     (phase-diagram sweep, sweep/sweep_main.hpp)
//   morphogen screen [DECK.yaml] [-option value ...]  (Turing screen, sweep/screen_main.hpp)
//   morphogen -help | -help petsc | --version         (app/command_line.hpp)
//
// The entry point: the top layer, above app and sweep (which sits on app), so neither of them
// needs to know about the other. Exit codes: 0 success, 1 bad input or a diverged run (one-line
// message), 2 an internal PETSc error (PETSc prints its trace), 3 stopped by SIGUSR1/SIGTERM or
// -max_walltime after writing a checkpoint (resubmit with -restart latest), 4 an output file
// could not be written.
#include "app/command_line.hpp"
#include "app/run_main.hpp"
#include "cli/exit_file.hpp"
#include "core/collective_error.hpp"
#include "core/options.hpp"
#include "core/petsc_handle.hpp"
#include "core/stop_signal.hpp"
#include "core/user_error.hpp"
#include "sweep/screen_main.hpp"
#include "sweep/sweep_main.hpp"

#include <cstdio>
#include <exception>
#include <string>

using namespace morphogen;

int main(int argc, char** argv) {
  // -h/--help/-help, --version/-version and -options_file are ours (app/command_line.hpp).
  const CommandLine cl = take_command_line(&argc, argv);
  PetscCall(PetscInitialize(&argc, &argv, nullptr,
                            "morphogen [DECK.yaml] [-option value ...]; -help lists options\n"));
  install_stop_signal_handlers();
  const double wall_start = MPI_Wtime(); // -max_walltime counts from here
  int rc = 0;
  try {
    if (!cl.error.empty()) throw UserError(cl.error);
    if (cl.version) {
      print_version(PETSC_COMM_WORLD);
    } else {
      if (cl.help != CommandLine::Help::None) Options::request_help();
      const std::string cmd = argc > 1 ? argv[1] : "";
      rc = cmd == "sweep"    ? sweep::run_sweep(&argc, &argv, cl.options_files)
           : cmd == "screen" ? sweep::run_screen(&argc, &argv, cl.options_files)
                             : run_main(&argc, &argv, wall_start, cl.options_files);
    }
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
  write_exit_file(rc); // for job scripts (cli/exit_file.hpp)
  // Unused-option warnings are ours (check_unused); keep PETSc quiet about them at exit.
  PetscCall(PetscOptionsSetValue(nullptr, "-options_left", "0"));
  PetscCall(PetscFinalize());
  return rc;
}
