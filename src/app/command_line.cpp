#include "app/command_line.hpp"

#include "app/log_file_check.hpp"

#include <petscsys.h>

namespace morphogen {

namespace {

// True (and the help mode set) for -h, --help, -help; "-help petsc" keeps -help for PETSc.
bool take_help(const std::string& a, const char* next, CommandLine& cl, bool& keep, bool& skip) {
  if (a != "-h" && a != "--help" && a != "-help") return false;
  const bool petsc = a == "-help" && next && std::string(next) == "petsc";
  if (cl.help != CommandLine::Help::Petsc)
    cl.help = petsc ? CommandLine::Help::Petsc : CommandLine::Help::Morphogen;
  keep = petsc; // PETSc sees -help (without "petsc")
  skip = petsc;
  return true;
}

// True (and cl.error set) for -log_view/-log_trace with a file that cannot be written.
bool take_bad_log_file(const std::string& a, const char* next, CommandLine& cl) {
  if ((a != "-log_view" && a != "-log_trace") || !next || next[0] == '-') return false;
  const std::string why = log_file_problem(a, next);
  if (why.empty()) return false;
  if (cl.error.empty()) cl.error = why;
  return true;
}

} // namespace

CommandLine take_command_line(int* argc, char** argv) {
  CommandLine cl;
  int out = 1;
  for (int i = 1; i < *argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < *argc ? argv[i + 1] : nullptr;
    bool keep = false, skip = false;
    if (take_help(a, next, cl, keep, skip)) {
      if (keep) argv[out++] = argv[i];
      i += skip ? 1 : 0;
    } else if (a == "-version" || a == "--version") {
      cl.version = true;
    } else if (a == "-options_file" || a == "-options_file_yaml") {
      if (!next || next[0] == '\0' || (next[0] == '-' && next[1] != '\0')) {
        if (cl.error.empty()) cl.error = a + ": needs a file name (" + a + " FILE)";
        continue;
      }
      cl.options_files.push_back({a.substr(1), next});
      ++i;
    } else if (take_bad_log_file(a, next, cl)) {
      ++i; // dropped, so that PETSc does not fail on it (at PetscInitialize or PetscFinalize)
    } else {
      argv[out++] = argv[i];
    }
  }
  *argc = out;
  argv[out] = nullptr;
  return cl;
}

void print_version(MPI_Comm comm) {
  char petsc[256] = "";
  PetscGetVersion(petsc, sizeof petsc);
  char mpi[MPI_MAX_LIBRARY_VERSION_STRING] = "";
  int len = 0;
  MPI_Get_library_version(mpi, &len);
  std::string m(mpi, static_cast<size_t>(len));
  if (const auto nl = m.find_first_of("\r\n,"); nl != std::string::npos) m.resize(nl);
  PetscPrintf(comm, "morphogen %s\n%s\n%s\n", MORPHOGEN_VERSION, petsc, m.c_str());
}

} // namespace morphogen
