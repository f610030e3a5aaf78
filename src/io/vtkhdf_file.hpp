// VTKHDF ImageData files: the snapshot and checkpoint format ParaView opens without a plug-in.
//
//   /VTKHDF                 attributes Version int32[2] = {1,0}, Type = "ImageData",
//                           WholeExtent int32[6] = {0,nx-1, 0,ny-1, 0,nz-1} ({.., 0,0} in 2-D),
//                           Origin double[3] (the first cell centre, h/2 per axis; z = 0 in
//                           2-D), Spacing double[3] = h, Direction double[9] (identity)
//   /VTKHDF/PointData/<s>   one dataset per species, shape (nz, ny, nx) -- always three
//                           dimensions, nz = 1 for 2-D runs -- float32 or float64
//   /morphogen              attributes (time, step, model, ... for checkpoints: see checkpoint.hpp)
//
// Cell-centred values are stored as VTK points at the cell centres, the layout every VTKHDF
// reader opens (ParaView 5.11's reads no image cell data), so a .vtkhdf file's bounds are the
// cell centres, h/2 .. (n - 1/2) h; the .xmf index (series_index.hpp) presents the same datasets
// as cell data with bounds = the domain. Files of an earlier development version stored them as
// /VTKHDF/CellData/<s> of an image of the cell corners (WholeExtent {0,nx, 0,ny, 0,nz}, z 0..0 in
// 2-D, Origin 0): they are still read (inspect_vtkhdf and VtkHdfIO::read accept both layouts).
// Fields are written and read collectively (MPI-IO): each rank transfers the hyperslab of its
// owned box straight from or into its ghosted local array (an HDF5 memory selection, no copy
// and no gather), so a file written on any number of ranks loads on any other.
#pragma once

#include "grid/grid.hpp"

#include <hdf5.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace morphogen::io {

// Scalar attributes of the /morphogen group (identical on every rank).
struct H5Attributes {
  std::vector<std::pair<std::string, double>> reals;
  std::vector<std::pair<std::string, long long>> ints;
  std::vector<std::pair<std::string, std::string>> strings;
  const double* real(const std::string& name) const;
  const long long* integer(const std::string& name) const;
  const std::string* string(const std::string& name) const;
};

// What a file holds, read without PETSc (one rank).
struct ImageInfo {
  std::array<long long, 3> n{1, 1, 1};                     // cells per axis (1 along z in 2-D)
  std::array<double, 3> origin{0, 0, 0}, spacing{1, 1, 1}; // the file's Origin and Spacing
  bool cell_data = false;          // false: /VTKHDF/PointData; true: the CellData layout
  std::vector<std::string> arrays; // datasets of /VTKHDF/PointData (or CellData)
  int precision = 8;               // bytes per value of the first array
  H5Attributes attributes;         // /morphogen, if present
  const char* group() const { return cell_data ? "CellData" : "PointData"; }
  std::string to_json() const;
  static ImageInfo from_json(const std::string& text);
};

// Opens `path` with the serial HDF5 library and checks the VTKHDF layout. Returns nullopt and
// the reason (missing, truncated, not VTKHDF ImageData, ...) when the file cannot be used.
// Call on one rank only; HDF5's own error printing is suppressed.
std::optional<ImageInfo> inspect_vtkhdf(const std::string& path, std::string& why);

class VtkHdfIO {
public:
  explicit VtkHdfIO(const Grid& grid);

  // Collective. Writes the owned cells of the ghosted local vectors `fields` (named by `names`)
  // and the /morphogen attributes to `path` (created or truncated). Returns "" on success or
  // PETSc's / HDF5's message (no trace is printed).
  std::string write(const std::string& path, const std::vector<std::string>& names,
                    const std::vector<Vec>& fields, bool single_precision,
                    const H5Attributes& attributes) const;

  // Collective. Reads the datasets `names` into the owned cells of the ghosted local vectors
  // (ghosts are not updated), from /VTKHDF/PointData or, in files of the CellData layout,
  // /VTKHDF/CellData. The file's extents must match the grid. Returns "" or a message.
  std::string read(const std::string& path, const std::vector<std::string>& names,
                   const std::vector<Vec>& fields) const;

private:
  PetscErrorCode write_impl(const std::string& path, const std::vector<std::string>& names,
                            const std::vector<Vec>& fields, bool single_precision,
                            const H5Attributes& attributes) const;
  PetscErrorCode read_impl(const std::string& path, const std::vector<std::string>& names,
                           const std::vector<Vec>& fields) const;
  // One dataset <group>/<name> of shape (nz, ny, nx) from / into the owned cells of `local`.
  PetscErrorCode write_field(hid_t group, const std::string& name, Vec local,
                             bool single_precision) const;
  PetscErrorCode read_field(hid_t group, const std::string& name, Vec local) const;

  const Grid& grid_;
};

} // namespace morphogen::io
