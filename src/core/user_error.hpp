// User-facing errors: bad options, deck keys, expressions, files, unstable dt.
// Thrown only from morphogen's own C++ code (never through PETSc's C callbacks); caught in
// main(), which prints the one-line message on rank 0 and exits non-zero. The message names the
// option or deck key, the value and what is allowed.
#pragma once

#include <stdexcept>
#include <string>

namespace morphogen {

struct UserError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

} // namespace morphogen
