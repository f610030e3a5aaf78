// The clamp of negative concentrations as a pure kernel: max(v, floor) that keeps NaN.
// `v > floor ? v : floor` turns a NaN into the floor and so erases a diverged cell before the
// NaN guard sees it. `floor > v ? floor : v` passes NaN through and is still one vector
// instruction (x86 MAXPD returns its second operand when the compare fails, as this does). It
// equals the old form for every non-NaN v except v = -0 with floor = +0 (it keeps -0), which
// the clamp's own outputs never produce: results stay bitwise those of the old form.
#pragma once

#include "core/host_device.hpp"

namespace morphogen {

MG_HD inline double clamp_to_floor(double v, double floor) {
  return floor > v ? floor : v;
}

} // namespace morphogen
