// Cell arrays of the run's grid in any HDF5 file (a VTKHDF snapshot of ours or of another
// code, or a plain HDF5 file), read block-wise: each rank reads only its owned box.
//
// Dataset names: a name starting with '/' is a full path; a bare name N is looked up as
// /VTKHDF/PointData/N, /VTKHDF/CellData/N, /N, in that order (our snapshots write
// /VTKHDF/PointData/<name>; VTKHDF ImageData cell arrays of other writers live in CellData).
// Layout: C order with x fastest, i.e. value of cell (i, j, k) at flat index
// i + nx (j + ny k). Accepted shapes (leading extents of 1 ignored on both sides): the grid's
// (nz, ny, nx) -- (ny, nx) in 2-D -- or a flat array of nx ny nz values (VTKHDF cell arrays).
// Any integer or floating-point type (converted to double on reading).
#pragma once

#include "grid/grid.hpp"

#include <string>
#include <vector>

namespace morphogen::io {

// One rank (serial HDF5). Checks that `path` is a readable HDF5 file whose datasets `names`
// exist, hold numbers and fit a grid of n = {nx, ny, nz} cells; `resolved` gets their full
// paths. Returns "" or the reason ("no such file", "not an HDF5 file", "no dataset ...",
// "dataset ... has 16 x 16 values (ny x nx), the run's grid 32 x 32 ...").
std::string probe_h5_arrays(const std::string& path, const std::vector<std::string>& names,
                            const std::array<PetscInt, 3>& n, std::vector<std::string>& resolved);

// One rank. A scalar numeric attribute given as "/object/path/name" (attribute `name` of the
// group or dataset /object/path; "/name": of the root group). Returns "" or the reason.
std::string read_h5_attribute(const std::string& path, const std::string& attribute, double& value);

// Collective over comm. Reads the cells of `box` (x fastest) of each dataset (full paths as
// from probe_h5_arrays, shapes already checked) of a grid of n cells, through MPI-IO
// (collective transfers); out[a] gets box.size() values. Returns "" or a message, the same on
// every rank.
std::string read_h5_block(MPI_Comm comm, const std::string& path,
                          const std::vector<std::string>& datasets,
                          const std::array<PetscInt, 3>& n, const Box& box,
                          std::vector<std::vector<double>>& out);

} // namespace morphogen::io
