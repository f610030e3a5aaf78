// The choice between two compiles of one row kernel that give bitwise the same results (the
// explicit rows with 256-bit and with 512-bit vectors, integrators/model_kernels.hpp), made by
// timing them in the run's own passes:
//   Auto: after kWarmup passes with the first kernel, the two alternate until each has run
//         at least kTrials passes and kMinSeconds in all (or kMaxTrials passes); then the one
//         with the smaller least pass time is kept for the rest of the run (the least: robust
//         against passes that an interrupt slowed down; many passes where passes are short).
//   Narrow / Wide: that kernel from the start.
// Each rank chooses for itself: the results do not depend on the choice.
#pragma once

#include "integrators/explicit_kernel.hpp"

#include <string>

namespace morphogen {

class KernelChoice {
public:
  using RowFn = void (*)(const ExplicitRow&);
  enum class Mode { Auto, Narrow, Wide };
  static constexpr int kWarmup = 1, kTrials = 4, kMaxTrials = 1024;
  static constexpr double kMinSeconds = 1e-3;

  KernelChoice(RowFn narrow, RowFn wide, Mode mode);

  // True while the passes are timed (Auto, until the choice is made).
  bool timing() const { return chosen_ < 0; }
  // The kernel for the next pass; after the pass, record() its wall time (any value once
  // timing() is false: the pass is only counted).
  RowFn next() const { return chosen_ == 1 || (chosen_ < 0 && trying_wide()) ? wide_ : narrow_; }
  void record(double seconds);
  // -1 while still timing, 0 narrow, 1 wide.
  int chosen() const { return chosen_; }
  // Passes recorded so far.
  long long runs() const { return runs_; }
  // "256-bit" / "512-bit" (what next() runs once chosen), with the least pass times when timed.
  std::string describe() const;

private:
  bool trying_wide() const { return passes_ >= kWarmup && (passes_ - kWarmup) % 2 == 1; }

  RowFn narrow_ = nullptr, wide_ = nullptr;
  int chosen_ = 0;
  int passes_ = 0;           // passes while choosing
  long long runs_ = 0;       // all passes
  double best_[2] = {0, 0};  // least pass time of narrow, wide
  double total_[2] = {0, 0}; // time of all their passes
};

// True where the wide compile uses 512-bit vectors (the build's CPU has AVX-512); elsewhere
// the two compiles are the same code and Auto keeps the narrow one without timing.
bool wide_vectors_available();

} // namespace morphogen
