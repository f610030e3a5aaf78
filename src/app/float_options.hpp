// The option of the process's subnormal handling (-flush_subnormals), read into
// core/float_env.hpp's setting.
#pragma once

#include "core/options.hpp"

namespace morphogen {

void read_float_env(Options& opt);

} // namespace morphogen
