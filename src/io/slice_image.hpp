// One x-y slice (z index k) of a distributed field, reduced for a quick-look image and gathered
// on rank 0 (io/block_mean_kernel.hpp has the reduction and its rank-independence).
// With max_size == 0 or a slice that fits (max(nx, ny) <= max_size) the image is the slice
// itself (io/slice_gather.hpp) and [lo, hi] its min/max; otherwise every rank reduces its owned
// cells to block sums, only those blocks are gathered (never the full slice), and [lo, hi] is
// the finite min/max of the full-resolution slice. Collective; the image is empty off rank 0.
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen::io {

struct SliceImage {
  int width = 0, height = 0; // pixels
  long long factor = 1;      // block side in cells (1: full resolution)
  double lo = 0, hi = 0;     // range of the slice's values (lo > hi: none finite)
  std::vector<double> value; // value[I + width * J], J = 0 the bottom row (rank 0)
};

SliceImage gather_xy_slice_image(const Grid& grid, const double* ghosted, PetscInt k,
                                 long long max_size);

} // namespace morphogen::io
