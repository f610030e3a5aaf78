// PETSc logging events around each phase of a run, reported by -log_view:
//   MgHalo (ghost exchange and boundary fill), MgExplicitSweep (the fused kernel sweep),
//   MgSetup (options, grid, fields), MgOutput (PNG images), MgReaction (split reaction
//   substep), MgDiffusion (split implicit diffusion substep).
#pragma once

#include <petsclog.h>

namespace morphogen {

struct LogEvents {
  PetscLogEvent halo, sweep, setup, output, reaction, diffusion;
};

// Registered on first use (after PetscInitialize).
const LogEvents& log_events();

// Scope guard: the event is active for the lifetime of the object (exception-safe).
class LogScope {
public:
  explicit LogScope(PetscLogEvent e) : e_(e) { (void)PetscLogEventBegin(e_, 0, 0, 0, 0); }
  ~LogScope() { (void)PetscLogEventEnd(e_, 0, 0, 0, 0); }
  LogScope(const LogScope&) = delete;
  LogScope& operator=(const LogScope&) = delete;

private:
  PetscLogEvent e_;
};

} // namespace morphogen
