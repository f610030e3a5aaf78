#include "cli/exit_file.hpp"

#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace morphogen {

void write_exit_file(int rc) {
  const char* path = std::getenv("MORPHOGEN_EXIT_FILE");
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (!path || !*path || rank != 0) return;
  const std::string tmp = std::string(path) + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) return;
  const bool ok = std::fprintf(f, "%d\n", rc) > 0;
  if (std::fclose(f) == 0 && ok) std::rename(tmp.c_str(), path);
}

} // namespace morphogen
