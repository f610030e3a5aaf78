#include "app/float_options.hpp"

#include "core/float_env.hpp"

namespace morphogen {

void read_float_env(Options& opt) {
  const bool on = opt.flag(
      "flush_subnormals", true,
      "flush subnormal numbers (|x| < 2.2e-308) to zero in arithmetic (x86 FTZ/DAZ, ARM FZ): "
      "fields decaying to zero otherwise run several times slower on many CPUs; false: IEEE "
      "gradual underflow (results differ only below 2.2e-308)");
  set_flush_subnormals(on);
}

} // namespace morphogen
