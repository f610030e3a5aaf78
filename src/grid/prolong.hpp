// Coarse-to-fine transfer for grid sequencing (Witkin-Kass section 5.2, Lawlor): each axis of
// the fine grid has twice the cells of the coarse one, cell-centred, so fine cell I sits at
// coarse index position I/2 - 1/4 and gets, per axis, 3/4 of its parent i = floor(I/2) and 1/4
// of the neighbour on its side (i - 1 for even I, i + 1 for odd I); tensor product in 2-D and
// 3-D (bilinear / trilinear, exact for functions linear in each coordinate). The coarse array
// must have current ghosts (halo and boundary rules); the fine grid must nest the coarse one
// (GridSpec::ranges = 2 x the coarse ranges), so every parent is in this rank's ghosted box.
#pragma once

#include "grid/grid.hpp"

namespace morphogen {

// Fill the owned cells of `fine_ghosted` from `coarse_ghosted`.
void prolong_cell_centred(const Grid& coarse, const double* coarse_ghosted, const Grid& fine,
                          double* fine_ghosted);

} // namespace morphogen
