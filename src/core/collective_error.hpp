// Collective user errors: a check that may fail on some ranks only (a parameter out of range in
// one rank's cells, say) must stop every rank with the same message, never hang the others.
// throw_if_any(comm, msg): every rank calls it; if any rank's msg is non-empty, the message of the
// lowest such rank is broadcast and every rank throws UserError with it.
#pragma once

#include <mpi.h>
#include <string>

namespace morphogen {

void throw_if_any(MPI_Comm comm, const std::string& local_message);

} // namespace morphogen
