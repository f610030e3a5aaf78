// A velocity computed by the run (the stable-fluids solver, operators/fluid_solver.hpp) that
// the advection stage reads each step instead of the -velocity_x/_y expressions: one ghosted
// local array per axis on the run's grid, owned cells current.
#pragma once

#include <petscvec.h>

#include <string>

namespace morphogen {

class VelocitySource {
public:
  virtual ~VelocitySource() = default;
  // Component d (d < dim) as a ghosted local Vec on the run's grid; owned cells current.
  virtual Vec component(int d) const = 0;
  // A bound of max |u| expected over the run (sizes the advection halo at the start).
  virtual double speed_bound() const = 0;
  // The option that selects this velocity, for messages (e.g. "-fluid cavity").
  virtual std::string option_text() const = 0;
  // One line for the run banner.
  virtual std::string describe() const = 0;
};

} // namespace morphogen
