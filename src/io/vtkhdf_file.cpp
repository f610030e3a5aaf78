#include "io/vtkhdf_file.hpp"

#include "io/h5_handle.hpp"

#include <hdf5.h>
#include <nlohmann/json.hpp>
#include <petscdmda.h>
#include <petscviewerhdf5.h>

#include <array>
#include <cstring>

namespace morphogen::io {

namespace {

// PETSc error (PETSC_ERR_LIB) when an HDF5 call returns a negative status or id.
#define MG_H5(...)                                                                                 \
  do {                                                                                             \
    if ((__VA_ARGS__) < 0)                                                                         \
      SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "HDF5 call failed: %s", #__VA_ARGS__);               \
  } while (0)
#define MG_H5_ID(id, ...)                                                                          \
  do {                                                                                             \
    (id) = (__VA_ARGS__);                                                                          \
    if ((id) < 0) SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "HDF5 call failed: %s", #__VA_ARGS__);   \
  } while (0)

// HDF5 handle closed on scope exit.
struct H5Id {
  hid_t id = -1;
  herr_t (*close)(hid_t) = nullptr;
  H5Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  ~H5Id() {
    if (id >= 0 && close) close(id);
  }
  bool ok() const { return id >= 0; }
  operator hid_t() const { return id; }
};

using H5Quiet = H5Silent;

PetscErrorCode write_array_attr(hid_t obj, const char* name, hid_t mem_type, hid_t file_type,
                                hsize_t n, const void* data) {
  PetscFunctionBeginUser;
  hid_t space, attr;
  MG_H5_ID(space, H5Screate_simple(1, &n, nullptr));
  MG_H5_ID(attr, H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT));
  MG_H5(H5Awrite(attr, mem_type, data));
  MG_H5(H5Aclose(attr));
  MG_H5(H5Sclose(space));
  PetscFunctionReturn(0);
}

PetscErrorCode write_scalar_attr(hid_t obj, const char* name, hid_t mem_type, hid_t file_type,
                                 const void* data) {
  PetscFunctionBeginUser;
  hid_t space, attr;
  MG_H5_ID(space, H5Screate(H5S_SCALAR));
  MG_H5_ID(attr, H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT));
  MG_H5(H5Awrite(attr, mem_type, data));
  MG_H5(H5Aclose(attr));
  MG_H5(H5Sclose(space));
  PetscFunctionReturn(0);
}

// Fixed-length ASCII string attribute (what VTK's reader expects for /VTKHDF Type).
PetscErrorCode write_string_attr(hid_t obj, const char* name, const std::string& value) {
  PetscFunctionBeginUser;
  hid_t type;
  MG_H5_ID(type, H5Tcopy(H5T_C_S1));
  MG_H5(H5Tset_size(type, value.empty() ? 1 : value.size()));
  MG_H5(H5Tset_strpad(type, H5T_STR_NULLPAD));
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  PetscCall(write_scalar_attr(obj, name, type, type, padded.data()));
  MG_H5(H5Tclose(type));
  PetscFunctionReturn(0);
}

bool read_attr_doubles(hid_t obj, const char* name, double* out, size_t n) {
  if (H5Aexists(obj, name) <= 0) return false;
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return false;
  H5Id s(H5Aget_space(a), H5Sclose);
  if (H5Sget_simple_extent_npoints(s) != static_cast<hssize_t>(n)) return false;
  return H5Aread(a, H5T_NATIVE_DOUBLE, out) >= 0;
}

bool read_attr_ints(hid_t obj, const char* name, long long* out, size_t n) {
  if (H5Aexists(obj, name) <= 0) return false;
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return false;
  H5Id s(H5Aget_space(a), H5Sclose);
  if (H5Sget_simple_extent_npoints(s) != static_cast<hssize_t>(n)) return false;
  return H5Aread(a, H5T_NATIVE_LLONG, out) >= 0;
}

bool read_attr_string(hid_t obj, const char* name, std::string& out) {
  if (H5Aexists(obj, name) <= 0) return false;
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return false;
  H5Id t(H5Aget_type(a), H5Tclose);
  if (H5Tget_class(t) != H5T_STRING || H5Tis_variable_str(t) > 0) return false;
  std::vector<char> buf(H5Tget_size(t) + 1, '\0');
  if (H5Aread(a, t, buf.data()) < 0) return false;
  out.assign(buf.data());
  return true;
}

// Collects the /morphogen attributes by type.
herr_t collect_attr(hid_t obj, const char* name, const H5A_info_t*, void* data) {
  auto* attrs = static_cast<H5Attributes*>(data);
  H5Id a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!a.ok()) return 0;
  H5Id t(H5Aget_type(a), H5Tclose);
  switch (H5Tget_class(t)) {
  case H5T_FLOAT: {
    double v;
    if (read_attr_doubles(obj, name, &v, 1)) attrs->reals.emplace_back(name, v);
    break;
  }
  case H5T_INTEGER: {
    long long v;
    if (read_attr_ints(obj, name, &v, 1)) attrs->ints.emplace_back(name, v);
    break;
  }
  case H5T_STRING: {
    std::string v;
    if (read_attr_string(obj, name, v)) attrs->strings.emplace_back(name, v);
    break;
  }
  default:
    break;
  }
  return 0;
}

herr_t collect_dataset(hid_t group, const char* name, const H5L_info_t*, void* data) {
  H5O_info_t info;
  if (H5Oget_info_by_name2(group, name, &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0 &&
      info.type == H5O_TYPE_DATASET)
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
  return 0;
}

} // namespace

const double* H5Attributes::real(const std::string& name) const {
  for (const auto& [k, v] : reals)
    if (k == name) return &v;
  return nullptr;
}
const long long* H5Attributes::integer(const std::string& name) const {
  for (const auto& [k, v] : ints)
    if (k == name) return &v;
  return nullptr;
}
const std::string* H5Attributes::string(const std::string& name) const {
  for (const auto& [k, v] : strings)
    if (k == name) return &v;
  return nullptr;
}

std::string ImageInfo::to_json() const {
  nlohmann::json j;
  j["n"] = n;
  j["origin"] = origin;
  j["spacing"] = spacing;
  j["cell_data"] = cell_data;
  j["arrays"] = arrays;
  j["precision"] = precision;
  j["reals"] = attributes.reals;
  j["ints"] = attributes.ints;
  j["strings"] = attributes.strings;
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

ImageInfo ImageInfo::from_json(const std::string& text) {
  const auto j = nlohmann::json::parse(text);
  ImageInfo info;
  info.n = j["n"].get<std::array<long long, 3>>();
  info.origin = j["origin"].get<std::array<double, 3>>();
  info.spacing = j["spacing"].get<std::array<double, 3>>();
  info.cell_data = j["cell_data"].get<bool>();
  info.arrays = j["arrays"].get<std::vector<std::string>>();
  info.precision = j["precision"].get<int>();
  info.attributes.reals = j["reals"].get<std::vector<std::pair<std::string, double>>>();
  info.attributes.ints = j["ints"].get<std::vector<std::pair<std::string, long long>>>();
  info.attributes.strings = j["strings"].get<std::vector<std::pair<std::string, std::string>>>();
  return info;
}

std::optional<ImageInfo> inspect_vtkhdf(const std::string& path, std::string& why) {
  H5Quiet quiet;
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    FILE* f = std::fopen(path.c_str(), "rb");
    why = f ? "not a readable HDF5 file (truncated or corrupt)" : "no such file";
    if (f) std::fclose(f);
    return std::nullopt;
  }
  H5Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) {
    why = "HDF5 cannot open it (truncated or corrupt)";
    return std::nullopt;
  }
  if (H5Lexists(file, "VTKHDF", H5P_DEFAULT) <= 0) {
    why = "no /VTKHDF group (not a VTKHDF file)";
    return std::nullopt;
  }
  H5Id vtk(H5Gopen2(file, "VTKHDF", H5P_DEFAULT), H5Gclose);
  std::string type;
  long long extent[6];
  ImageInfo info;
  if (!vtk.ok() || !read_attr_string(vtk, "Type", type) || type != "ImageData" ||
      !read_attr_ints(vtk, "WholeExtent", extent, 6) ||
      !read_attr_doubles(vtk, "Origin", info.origin.data(), 3) ||
      !read_attr_doubles(vtk, "Spacing", info.spacing.data(), 3)) {
    why = "/VTKHDF is not ImageData with WholeExtent, Origin and Spacing";
    return std::nullopt;
  }
  // PointData (the layout written): one point per cell, at its centre. CellData (written by an
  // intermediate development version): WholeExtent counts the cell corners (cells + 1; a flat axis
  // 0..0 holds one layer of cells).
  info.cell_data =
      H5Lexists(vtk, "PointData", H5P_DEFAULT) <= 0 && H5Lexists(vtk, "CellData", H5P_DEFAULT) > 0;
  for (int d = 0; d < 3; ++d) {
    const long long span = extent[2 * d + 1] - extent[2 * d];
    info.n[d] = info.cell_data ? (span == 0 ? 1 : span) : span + 1;
  }
  const std::string group = info.group();
  if (H5Lexists(vtk, group.c_str(), H5P_DEFAULT) > 0) {
    H5Id pd(H5Gopen2(vtk, group.c_str(), H5P_DEFAULT), H5Gclose);
    if (pd.ok()) H5Literate(pd, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_dataset, &info.arrays);
    for (size_t a = 0; a < info.arrays.size(); ++a) {
      H5Id ds(H5Dopen2(pd, info.arrays[a].c_str(), H5P_DEFAULT), H5Dclose);
      H5Id sp(ds.ok() ? H5Dget_space(ds) : -1, H5Sclose);
      hsize_t dims[4] = {0, 0, 0, 0};
      if (!sp.ok() || H5Sget_simple_extent_ndims(sp) != 3 ||
          H5Sget_simple_extent_dims(sp, dims, nullptr) != 3 ||
          static_cast<long long>(dims[0]) != info.n[2] ||
          static_cast<long long>(dims[1]) != info.n[1] ||
          static_cast<long long>(dims[2]) != info.n[0]) {
        why = "dataset /VTKHDF/" + group + "/" + info.arrays[a] + " does not match WholeExtent";
        return std::nullopt;
      }
      if (a == 0) {
        H5Id t(H5Dget_type(ds), H5Tclose);
        info.precision = static_cast<int>(H5Tget_size(t));
      }
    }
  }
  if (H5Lexists(file, "morphogen", H5P_DEFAULT) > 0) {
    H5Id mg(H5Gopen2(file, "morphogen", H5P_DEFAULT), H5Gclose);
    if (mg.ok()) {
      hsize_t idx = 0;
      H5Aiterate2(mg, H5_INDEX_NAME, H5_ITER_INC, &idx, collect_attr, &info.attributes);
    }
  }
  return info;
}

VtkHdfIO::VtkHdfIO(const Grid& grid) : grid_(grid) {}

namespace {

// The owned box of `grid` as a hyperslab of the (nz, ny, nx) dataset space `file` and of the
// (gz, gy, gx) ghosted local array `mem` (z slowest; 2-D grids have nz = gz = 1).
PetscErrorCode select_owned(const Grid& grid, hid_t file, hid_t mem) {
  PetscFunctionBeginUser;
  const Box &ob = grid.owned(), &gb = grid.ghosted();
  hsize_t fstart[3], mstart[3], count[3];
  for (int d = 0; d < 3; ++d) { // HDF5 order: z, y, x
    fstart[2 - d] = static_cast<hsize_t>(ob.s[d]);
    mstart[2 - d] = static_cast<hsize_t>(ob.s[d] - gb.s[d]);
    count[2 - d] = static_cast<hsize_t>(ob.m[d]);
  }
  MG_H5(H5Sselect_hyperslab(file, H5S_SELECT_SET, fstart, nullptr, count, nullptr));
  MG_H5(H5Sselect_hyperslab(mem, H5S_SELECT_SET, mstart, nullptr, count, nullptr));
  PetscFunctionReturn(0);
}

// Dataspaces of the grid's (nz, ny, nx) dataset and of this rank's ghosted local array.
std::array<hsize_t, 3> file_dims(const Grid& grid) {
  const auto& n = grid.spec().n;
  return {static_cast<hsize_t>(grid.dim() == 3 ? n[2] : 1), static_cast<hsize_t>(n[1]),
          static_cast<hsize_t>(n[0])};
}
std::array<hsize_t, 3> mem_dims(const Grid& grid) {
  const Box& gb = grid.ghosted();
  return {static_cast<hsize_t>(gb.m[2]), static_cast<hsize_t>(gb.m[1]),
          static_cast<hsize_t>(gb.m[0])};
}

bool one_rank(MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  return size == 1;
}

// A new file for one rank's POSIX driver, without HDF5's file lock (as the MPI-IO path: file
// systems mounted without flock, as some Lustre sites, would refuse it), whose close also closes
// any object an error path left open; negative on failure.
hid_t create_serial(const std::string& path) {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (fapl < 0) return -1;
  hid_t f = -1;
  if (H5Pset_file_locking(fapl, false, true) >= 0 &&
      H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) >= 0)
    f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  return f;
}

// A transfer property list for collective MPI-IO (every rank takes part in every dataset's
// write or read), or the default one for a file of one rank's POSIX driver; negative on failure.
hid_t collective_xfer(bool mpio = true) {
  const hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
  if (mpio && dxpl >= 0 && H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0) {
    H5Pclose(dxpl);
    return -1;
  }
  return dxpl;
}

} // namespace

PetscErrorCode VtkHdfIO::write_field(hid_t group, const std::string& name, Vec local,
                                     bool single_precision) const {
  PetscFunctionBeginUser;
  const auto fd = file_dims(grid_), md = mem_dims(grid_);
  H5Id fspace(H5Screate_simple(3, fd.data(), nullptr), H5Sclose);
  H5Id mspace(H5Screate_simple(3, md.data(), nullptr), H5Sclose);
  H5Id dxpl(collective_xfer(!one_rank(grid_.comm())), H5Pclose);
  MG_H5(fspace.id);
  MG_H5(mspace.id);
  MG_H5(dxpl.id);
  PetscCall(select_owned(grid_, fspace, mspace));
  H5Id ds(H5Dcreate2(group, name.c_str(), single_precision ? H5T_IEEE_F32LE : H5T_IEEE_F64LE,
                     fspace, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
          H5Dclose);
  MG_H5(ds.id);
  const PetscScalar* a;
  PetscCall(VecGetArrayRead(local, &a));
  const herr_t st = H5Dwrite(ds, H5T_NATIVE_DOUBLE, mspace, fspace, dxpl, a);
  PetscCall(VecRestoreArrayRead(local, &a));
  MG_H5(st);
  PetscFunctionReturn(0);
}

PetscErrorCode VtkHdfIO::read_field(hid_t group, const std::string& name, Vec local) const {
  PetscFunctionBeginUser;
  const auto fd = file_dims(grid_), md = mem_dims(grid_);
  H5Id ds(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.ok()) SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED, "no dataset %s", name.c_str());
  H5Id fspace(H5Dget_space(ds), H5Sclose);
  MG_H5(fspace.id);
  hsize_t have[3] = {0, 0, 0};
  if (H5Sget_simple_extent_ndims(fspace) != 3 ||
      H5Sget_simple_extent_dims(fspace, have, nullptr) < 0 || have[0] != fd[0] ||
      have[1] != fd[1] || have[2] != fd[2])
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_FILE_UNEXPECTED,
            "dataset %s is not of shape (%llu, %llu, %llu)", name.c_str(),
            static_cast<unsigned long long>(fd[0]), static_cast<unsigned long long>(fd[1]),
            static_cast<unsigned long long>(fd[2]));
  H5Id mspace(H5Screate_simple(3, md.data(), nullptr), H5Sclose);
  H5Id dxpl(collective_xfer(), H5Pclose);
  MG_H5(mspace.id);
  MG_H5(dxpl.id);
  PetscCall(select_owned(grid_, fspace, mspace));
  PetscScalar* a;
  PetscCall(VecGetArray(local, &a));
  const herr_t st = H5Dread(ds, H5T_NATIVE_DOUBLE, mspace, fspace, dxpl, a);
  PetscCall(VecRestoreArray(local, &a));
  MG_H5(st);
  PetscFunctionReturn(0);
}

PetscErrorCode VtkHdfIO::write_impl(const std::string& path, const std::vector<std::string>& names,
                                    const std::vector<Vec>& fields, bool single_precision,
                                    const H5Attributes& attributes) const {
  PetscFunctionBeginUser;
  // On one rank HDF5's POSIX driver (default file access): an MPI-IO open and close cost about
  // 1.5 ms, which a sweep of small runs would pay per point. Else PETSc's viewer, collective.
  PetscViewer v = nullptr;
  const bool one = one_rank(grid_.comm());
  H5Id serial(one ? create_serial(path) : H5I_INVALID_HID, H5Fclose);
  hid_t file = serial.id, vtk, mg;
  if (one) {
    MG_H5(file);
  } else {
    PetscCall(PetscViewerHDF5Open(grid_.comm(), path.c_str(), FILE_MODE_WRITE, &v));
    PetscCall(PetscViewerHDF5SetCollective(v, PETSC_TRUE)); // MPI-IO collective transfers
    PetscCall(PetscViewerHDF5GetFileId(v, &file));
  }
  {
    H5Id root(H5Gcreate2(file, "/VTKHDF", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    H5Id points(H5Gcreate2(file, "/VTKHDF/PointData", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                H5Gclose);
    MG_H5(root.id);
    MG_H5(points.id);
    for (size_t s = 0; s < fields.size(); ++s)
      PetscCall(write_field(points, names[s], fields[s], single_precision));
  }
  MG_H5_ID(vtk, H5Gopen2(file, "/VTKHDF", H5P_DEFAULT));
  const auto& sp = grid_.spec();
  const int version[2] = {1, 0};
  int extent[6] = {0, 0, 0, 0, 0, 0};
  double origin[3] = {0, 0, 0}, spacing[3] = {sp.h(0), sp.h(1), sp.h(0)};
  const double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int d = 0; d < grid_.dim(); ++d) { // one point per cell, at its centre
    extent[2 * d + 1] = static_cast<int>(sp.n[d] - 1);
    origin[d] = 0.5 * sp.h(d);
    spacing[d] = sp.h(d);
  }
  PetscCall(write_array_attr(vtk, "Version", H5T_NATIVE_INT, H5T_STD_I32LE, 2, version));
  PetscCall(write_string_attr(vtk, "Type", "ImageData"));
  PetscCall(write_array_attr(vtk, "WholeExtent", H5T_NATIVE_INT, H5T_STD_I32LE, 6, extent));
  PetscCall(write_array_attr(vtk, "Origin", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, 3, origin));
  PetscCall(write_array_attr(vtk, "Spacing", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, 3, spacing));
  PetscCall(write_array_attr(vtk, "Direction", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, 9, direction));
  MG_H5(H5Gclose(vtk));

  MG_H5_ID(mg, H5Gcreate2(file, "/morphogen", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  for (const auto& [k, val] : attributes.reals)
    PetscCall(write_scalar_attr(mg, k.c_str(), H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, &val));
  for (const auto& [k, val] : attributes.ints)
    PetscCall(write_scalar_attr(mg, k.c_str(), H5T_NATIVE_LLONG, H5T_STD_I64LE, &val));
  for (const auto& [k, val] : attributes.strings)
    PetscCall(write_string_attr(mg, k.c_str(), val));
  MG_H5(H5Gclose(mg));
  if (v) PetscCall(PetscViewerDestroy(&v));
  if (one) {
    const hid_t f = serial.id;
    serial.id = H5I_INVALID_HID;
    MG_H5(H5Fclose(f));
  }
  PetscFunctionReturn(0);
}

PetscErrorCode VtkHdfIO::read_impl(const std::string& path, const std::vector<std::string>& names,
                                   const std::vector<Vec>& fields) const {
  PetscFunctionBeginUser;
  PetscViewer v;
  PetscCall(PetscViewerHDF5Open(grid_.comm(), path.c_str(), FILE_MODE_READ, &v));
  PetscCall(PetscViewerHDF5SetCollective(v, PETSC_TRUE));
  // PointData, or CellData in files of an intermediate development version (every rank reads the
  // links, so all take the same branch; the datasets have the same shape in both layouts).
  hid_t file;
  PetscCall(PetscViewerHDF5GetFileId(v, &file));
  const htri_t points = H5Lexists(file, "/VTKHDF/PointData", H5P_DEFAULT);
  const htri_t cells = points > 0 ? 0 : H5Lexists(file, "/VTKHDF/CellData", H5P_DEFAULT);
  {
    H5Id group(H5Gopen2(file, cells > 0 ? "/VTKHDF/CellData" : "/VTKHDF/PointData", H5P_DEFAULT),
               H5Gclose);
    MG_H5(group.id);
    for (size_t s = 0; s < fields.size(); ++s)
      PetscCall(read_field(group, names[s], fields[s]));
  }
  PetscCall(PetscViewerDestroy(&v));
  PetscFunctionReturn(0);
}

std::string VtkHdfIO::write(const std::string& path, const std::vector<std::string>& names,
                            const std::vector<Vec>& fields, bool single_precision,
                            const H5Attributes& attributes) const {
  H5Quiet quiet;
  return petsc_quietly(
      [&] { return write_impl(path, names, fields, single_precision, attributes); });
}

std::string VtkHdfIO::read(const std::string& path, const std::vector<std::string>& names,
                           const std::vector<Vec>& fields) const {
  H5Quiet quiet;
  return petsc_quietly([&] { return read_impl(path, names, fields); });
}

} // namespace morphogen::io
