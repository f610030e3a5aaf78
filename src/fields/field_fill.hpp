// Evaluate a ValueSpec at every owned cell of a grid into an array, with a range check.
// Collective: a bad value on any rank (out of range, NaN, expression error) stops every rank
// with the same one-line message (see core/collective_error.hpp).
#pragma once

#include "fields/value_spec.hpp"
#include "grid/grid.hpp"

namespace morphogen {

enum class ArrayLayout { Owned, Ghosted };

// Fill the owned cells of `a` (owned layout: a global Vec's array; ghosted: a local Vec's
// array, ghosts untouched). Values must lie in [lo, hi].
void fill_field(const Grid& grid, ValueSpec& spec, double* a, ArrayLayout layout, double lo,
                double hi, double t = 0.0);

} // namespace morphogen
