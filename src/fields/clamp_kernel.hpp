// The clamp of negative concentrations as a pure kernel: max(v, floor) that keeps NaN.
// `v > floor ? v : floor` turns a NaN into the floor and so erases a diverged cell before the
// NaN guard sees it; `!(v <= floor) ? v : floor` is the same for every non-NaN v (including
// v == floor and signed zeros: bitwise the old result) and passes NaN through. It is one
// unordered compare and a blend, so the fused explicit loop vectorises as before.
#pragma once

namespace morphogen {

inline double clamp_to_floor(double v, double floor) {
  return !(v <= floor) ? v : floor;
}

} // namespace morphogen
