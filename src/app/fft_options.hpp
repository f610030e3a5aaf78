// Options of the FFTW planning of the spectral solves (-fft_planner, -fft_wisdom), read into the
// process-wide setting of grid/fft_planning.hpp.
#pragma once

#include "core/options.hpp"

namespace morphogen {

void read_fft_planning(Options& opt);

} // namespace morphogen
