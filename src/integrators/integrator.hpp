// The one interface through which a run is advanced: the explicit, split and TS integrators
// each consume the run's term list (operators/term_list.hpp) and implement step().
#pragma once

#include "core/petsc_handle.hpp"

#include <vector>

namespace morphogen {

class Integrator {
public:
  virtual ~Integrator() = default;
  // Advance the ghosted local state vectors (one per species) from t to t + dt, constraints
  // applied; owned cells are current afterwards (ghosts may be stale). `step` is the number of
  // the step being taken, for messages.
  virtual void step(std::vector<VecH>& u, double t, double dt, PetscInt step) = 0;
};

} // namespace morphogen
