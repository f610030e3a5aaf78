// What main() takes off the command line before PetscInitialize, so that PETSc neither prints
// its own help banner for morphogen's `-help`, nor swallows `-h`, nor fails with a trace on a bad
// -options_file:
//   -h, --help, -help        morphogen's help (its options, grouped, with defaults and ranges)
//   -help petsc              PETSc's help as well (-help stays for PETSc: its banner and every
//                            PETSc object's options are printed as the objects are set up)
//   -version, --version      morphogen's version and PETSc's
//   -options_file F, -options_file_yaml F   loaded by load_deck (after the deck) instead
//   -log_view V, -log_trace V  only when V names a file that cannot be written
//                            (app/log_file_check.hpp): taken off, with `error` set
#pragma once

#include "app/deck.hpp"

#include <mpi.h>
#include <string>
#include <vector>

namespace morphogen {

struct CommandLine {
  enum class Help { None, Morphogen, Petsc };
  Help help = Help::None;
  bool version = false;
  std::vector<OptionsFileArg> options_files; // in the order given
  std::string error;                         // a one-line problem (-options_file without a file)
};

// Removes the arguments above from argv (argc shrinks; argv[0] stays). Pure: no PETSc, no MPI.
CommandLine take_command_line(int* argc, char** argv);

// Prints "morphogen VERSION" with PETSc's and MPI's versions on rank 0 of comm.
void print_version(MPI_Comm comm);

} // namespace morphogen
