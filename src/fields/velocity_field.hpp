// The velocity u(x, t) that carries advected species (operators/advection_stage.hpp), one
// component per axis, given by
//   -velocity_x EXPR -velocity_y EXPR [-velocity_z EXPR]   value expressions of x, y, z (cell
//        centres), t and the other value variables (fields/value_spec.hpp); default 0. A
//        component using t is re-evaluated whenever evaluate() is asked for a new time.
// Components are evaluated into any box of global cells, unwrapped along periodic axes (a cell
// outside [0, n) takes the value of its periodic image, so a wide halo needs no exchange).
// Values must be finite (a one-line UserError names the option, the value and the cell).
#pragma once

#include "core/options.hpp"
#include "fields/value_spec.hpp"

#include <array>
#include <memory>
#include <vector>

namespace morphogen {

class VelocityField {
public:
  // Reads -velocity_x, -velocity_y (and -velocity_z in 3-D) from opt.
  VelocityField(const Grid& grid, Options& opt, std::uint64_t seed, const std::string& base_dir);

  bool uses_time() const;
  // The option text of component d (for messages and the run banner).
  const std::string& text(int d) const { return spec_[d]->text(); }
  // Component d at every cell of `box` (x fastest), at time t. Collective (error check).
  void evaluate(int d, const Box& box, double t, double* out);
  // max over the grid's cells of |u_d| for each axis d, at time t (0 beyond dim). Collective.
  std::array<double, 3> max_abs(double t);

private:
  const Grid& grid_;
  std::vector<std::unique_ptr<ValueSpec>> spec_;
};

} // namespace morphogen
