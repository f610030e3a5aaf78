#include "io/h5_arrays.hpp"

#include "io/h5_handle.hpp"

#include <hdf5.h>

#include <cstdio>
#include <filesystem>

namespace morphogen::io {

namespace {

// True when every link along the absolute path exists and the last is a dataset.
bool is_dataset(hid_t file, const std::string& p) {
  size_t pos = 0;
  while ((pos = p.find('/', pos + 1)) != std::string::npos)
    if (H5Lexists(file, p.substr(0, pos).c_str(), H5P_DEFAULT) <= 0) return false;
  if (H5Lexists(file, p.c_str(), H5P_DEFAULT) <= 0) return false;
  H5O_info_t info;
  return H5Oget_info_by_name2(file, p.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) >= 0 &&
         info.type == H5O_TYPE_DATASET;
}

std::vector<std::string> candidates(const std::string& name) {
  if (!name.empty() && name[0] == '/') return {name};
  return {"/VTKHDF/PointData/" + name, "/VTKHDF/CellData/" + name, "/" + name};
}

herr_t collect(hid_t, const char* name, const H5O_info_t* info, void* data) {
  auto* v = static_cast<std::vector<std::string>*>(data);
  if (info->type == H5O_TYPE_DATASET && v->size() < 12) v->push_back("/" + std::string(name));
  return 0;
}

// "the file's datasets: /a, /b, ..." (at most 12) for a missing-dataset message.
std::string dataset_list(hid_t file) {
  std::vector<std::string> all;
  H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_INC, collect, &all, H5O_INFO_BASIC);
  if (all.empty()) return "the file holds no datasets";
  std::string s = "the file's datasets: ";
  for (size_t i = 0; i < all.size(); ++i)
    s += (i ? ", " : "") + all[i];
  return s + (all.size() == 12 ? ", ..." : "");
}

// Extents without their leading 1s.
std::vector<long long> stripped(const std::vector<long long>& d) {
  size_t f = 0;
  while (f + 1 < d.size() && d[f] == 1)
    ++f;
  return {d.begin() + static_cast<std::ptrdiff_t>(f), d.end()};
}

std::string extents(const std::vector<long long>& d) {
  std::string s;
  for (size_t i = 0; i < d.size(); ++i)
    s += (i ? " x " : "") + std::to_string(d[i]);
  return s;
}

std::vector<long long> dims_of(hid_t ds) {
  H5Handle sp(H5Dget_space(ds), H5Sclose);
  const int r = sp.ok() ? H5Sget_simple_extent_ndims(sp) : -1;
  std::vector<hsize_t> d(static_cast<size_t>(r > 0 ? r : 0));
  if (r > 0) H5Sget_simple_extent_dims(sp, d.data(), nullptr);
  return {d.begin(), d.end()};
}

std::vector<long long> grid_dims(const std::array<PetscInt, 3>& n) {
  return {static_cast<long long>(n[2]), static_cast<long long>(n[1]), static_cast<long long>(n[0])};
}

// "" when the dataset's extents fit the grid (structured or flat), else the reason.
std::string check_shape(const std::string& p, const std::vector<long long>& dims,
                        const std::array<PetscInt, 3>& n) {
  const auto want = stripped(grid_dims(n));
  const auto have = stripped(dims);
  const long long cells = static_cast<long long>(n[0] * n[1] * n[2]);
  if (have == want || (have.size() == 1 && have[0] == cells)) return {};
  const bool three = want.size() == 3;
  return "dataset " + p + " has " + (dims.empty() ? "no extents" : extents(dims)) +
         " values, the run's grid " + extents(want) + (three ? " (nz x ny x nx)" : " (ny x nx)") +
         " cells (allowed: those extents, x fastest, or a flat array of " + std::to_string(cells) +
         " values)";
}

// Selects box of a dataset of extents dims (checked by check_shape) in space.
herr_t select_box(hid_t space, const std::vector<long long>& dims, const std::array<PetscInt, 3>& n,
                  const Box& b) {
  const size_t r = dims.size();
  std::vector<hsize_t> start(r, 0), stride(r, 1), count(r, 1), block(r, 1);
  const auto have = stripped(dims);
  const bool flat = have.size() == 1 && have != stripped(grid_dims(n));
  if (!flat) { // right-aligned (k, j, i); extra leading extents are 1
    for (size_t q = 0; q < r && q < 3; ++q) {
      start[r - 1 - q] = static_cast<hsize_t>(b.s[q]);
      count[r - 1 - q] = static_cast<hsize_t>(b.m[q]);
    }
    return H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
  }
  // Flat: per z layer, m1 rows of m0 values, nx apart.
  for (PetscInt k = b.s[2]; k < b.s[2] + b.m[2]; ++k) {
    start[r - 1] = static_cast<hsize_t>(b.s[0] + n[0] * (b.s[1] + n[1] * k));
    stride[r - 1] = static_cast<hsize_t>(n[0]);
    count[r - 1] = static_cast<hsize_t>(b.m[1]);
    block[r - 1] = static_cast<hsize_t>(b.m[0]);
    if (H5Sselect_hyperslab(space, k == b.s[2] ? H5S_SELECT_SET : H5S_SELECT_OR, start.data(),
                            stride.data(), count.data(), block.data()) < 0)
      return -1;
  }
  return 0;
}

std::string file_problem(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return "no such file";
  if (H5Fis_hdf5(path.c_str()) <= 0) return "not an HDF5 file";
  return {};
}

} // namespace

std::string probe_h5_arrays(const std::string& path, const std::vector<std::string>& names,
                            const std::array<PetscInt, 3>& n, std::vector<std::string>& resolved) {
  H5Silent quiet;
  if (std::string why = file_problem(path); !why.empty()) return why;
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) return "HDF5 cannot open it (truncated or corrupt)";
  resolved.clear();
  for (const auto& name : names) {
    std::string found;
    for (const auto& c : candidates(name))
      if (found.empty() && is_dataset(file, c)) found = c;
    if (found.empty()) {
      const auto c = candidates(name);
      std::string tried;
      for (size_t i = 0; i < c.size(); ++i)
        tried += (i ? ", " : "") + c[i];
      return "no dataset '" + name + "' (looked for " + tried + "; " + dataset_list(file) + ")";
    }
    H5Handle ds(H5Dopen2(file, found.c_str(), H5P_DEFAULT), H5Dclose);
    H5Handle type(ds.ok() ? H5Dget_type(ds) : -1, H5Tclose);
    const H5T_class_t cls = type.ok() ? H5Tget_class(type) : H5T_NO_CLASS;
    if (cls != H5T_FLOAT && cls != H5T_INTEGER)
      return "dataset " + found +
             " does not hold numbers (an integer or floating-point type is "
             "needed)";
    if (std::string why = check_shape(found, dims_of(ds), n); !why.empty()) return why;
    resolved.push_back(found);
  }
  return {};
}

std::string read_h5_attribute(const std::string& path, const std::string& attribute,
                              double& value) {
  H5Silent quiet;
  if (std::string why = file_problem(path); !why.empty()) return why;
  const size_t slash = attribute.rfind('/');
  if (attribute.empty() || attribute[0] != '/' || slash + 1 >= attribute.size())
    return "attribute '" + attribute + "' is not of the form /object/name";
  const std::string object = slash == 0 ? "/" : attribute.substr(0, slash);
  const std::string name = attribute.substr(slash + 1);
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) return "HDF5 cannot open it (truncated or corrupt)";
  if (H5Aexists_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT) <= 0)
    return "no attribute '" + name + "' on " + object;
  H5Handle a(H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
  H5Handle sp(a.ok() ? H5Aget_space(a) : -1, H5Sclose);
  H5Handle type(a.ok() ? H5Aget_type(a) : -1, H5Tclose);
  const H5T_class_t cls = type.ok() ? H5Tget_class(type) : H5T_NO_CLASS;
  if (!sp.ok() || H5Sget_simple_extent_npoints(sp) != 1 || (cls != H5T_FLOAT && cls != H5T_INTEGER))
    return "attribute " + attribute + " is not a single number";
  if (H5Aread(a, H5T_NATIVE_DOUBLE, &value) < 0) return "attribute " + attribute + " unreadable";
  return {};
}

std::string read_h5_block(MPI_Comm comm, const std::string& path,
                          const std::vector<std::string>& datasets,
                          const std::array<PetscInt, 3>& n, const Box& box,
                          std::vector<std::vector<double>>& out) {
  H5Silent quiet;
  int failed = 0;
  out.assign(datasets.size(), std::vector<double>(static_cast<size_t>(box.size())));
  H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl), H5Fclose);
  H5Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE);
  const hsize_t m = static_cast<hsize_t>(box.size());
  for (size_t a = 0; a < datasets.size() && file.ok(); ++a) {
    H5Handle ds(H5Dopen2(file, datasets[a].c_str(), H5P_DEFAULT), H5Dclose);
    H5Handle space(ds.ok() ? H5Dget_space(ds) : -1, H5Sclose);
    H5Handle mem(H5Screate_simple(1, &m, nullptr), H5Sclose);
    if (!ds.ok() || !space.ok() || !mem.ok()) {
      failed = 1; // metadata is the same on every rank: all skip this collective read
      continue;
    }
    // Every rank takes part in the collective read, even after a local selection failure.
    if (select_box(space, dims_of(ds), n, box) < 0) {
      H5Sselect_none(space);
      H5Sselect_none(mem);
      failed = 1;
    }
    if (H5Dread(ds, H5T_NATIVE_DOUBLE, mem, space, dxpl, out[a].data()) < 0) failed = 1;
  }
  if (!file.ok()) failed = 1;
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm);
  return failed ? "reading it failed (HDF5 / MPI-IO error)" : std::string();
}

} // namespace morphogen::io
