#include "app/fft_options.hpp"

#include "grid/fft_planning.hpp"

namespace morphogen {

void read_fft_planning(Options& opt) {
  FftPlanning p;
  const std::string effort = opt.choice(
      "fft_planner", "measure", {"estimate", "measure", "patient"},
      "FFTW planning of the spectral diffusion and fluid solves: measure (time candidate "
      "algorithms once per shape, kept in -fft_wisdom), estimate (heuristic plans, no timing, "
      "slower transforms), patient (longer planning)");
  p.effort = effort == "estimate"  ? FftEffort::Estimate
             : effort == "patient" ? FftEffort::Patient
                                   : FftEffort::Measure;
  const std::string def = default_fft_wisdom_path();
  const std::string w =
      opt.string("fft_wisdom", def.empty() ? "none" : def,
                 "FFTW wisdom file read before planning and extended with newly timed plans, so "
                 "later runs re-create the same plans (bitwise-reproducible runs and restarts); "
                 "none: plans are timed in every run");
  p.wisdom = w == "none" ? "" : w;
  set_fft_planning(p);
}

} // namespace morphogen
