#include "integrators/kernel_choice.hpp"

#include <algorithm>
#include <cstdio>

namespace morphogen {

bool wide_vectors_available() {
#ifdef __AVX512F__
  return true;
#else
  return false;
#endif
}

KernelChoice::KernelChoice(RowFn narrow, RowFn wide, Mode mode) : narrow_(narrow), wide_(wide) {
  if (mode == Mode::Wide)
    chosen_ = 1;
  else if (mode == Mode::Auto && wide_vectors_available() && narrow != wide)
    chosen_ = -1;
  else
    chosen_ = 0;
}

void KernelChoice::record(double seconds) {
  ++runs_;
  if (chosen_ >= 0) return;
  if (passes_ >= kWarmup) {
    const int w = trying_wide() ? 1 : 0;
    if (passes_ < kWarmup + 2 || seconds < best_[w]) best_[w] = seconds;
    total_[w] += seconds;
  }
  ++passes_;
  const int each = (passes_ - kWarmup) / 2; // passes of each kernel so far
  if (each >= kMaxTrials || (each >= kTrials && std::min(total_[0], total_[1]) >= kMinSeconds))
    chosen_ = best_[1] < best_[0] ? 1 : 0;
}

std::string KernelChoice::describe() const {
  std::string s = chosen_ < 0                                ? "256-bit and 512-bit alternating"
                  : chosen_ == 1 && wide_vectors_available() ? "512-bit"
                                                             : "256-bit";
  if (passes_ > kWarmup + 1) {
    char buf[128];
    std::snprintf(buf, sizeof buf, " (%sleast pass 256-bit %.3g s, 512-bit %.3g s)",
                  chosen_ < 0 ? "still timing: " : "", best_[0], best_[1]);
    s += buf;
  }
  return s;
}

} // namespace morphogen
