// A table of columns in an HDF5 file: see h5_table.hpp.
#include "io/h5_table.hpp"

#include "io/h5_handle.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace morphogen::io {

namespace {

// This rank's pieces sorted by first row (an HDF5 union selection is traversed in file order),
// each with where its rows start in the rank's column data.
struct Piece {
  long long first, count, at;
};

std::vector<Piece> sorted_pieces(const H5TableData& d) {
  std::vector<Piece> out;
  long long at = 0;
  for (const auto& [first, count] : d.pieces) {
    if (count > 0) out.push_back({first, count, at});
    at += count;
  }
  std::sort(out.begin(), out.end(),
            [](const Piece& a, const Piece& b) { return a.first < b.first; });
  return out;
}

// Creates dataset `name` of nrows values of `type` and writes this rank's rows (collective).
template <class T>
bool write_column(hid_t file, hid_t dxpl, const std::string& name, hid_t file_type, hid_t mem_type,
                  long long nrows, const std::vector<T>& values, const std::vector<Piece>& pieces) {
  std::vector<T> buf; // the rows in file order
  buf.reserve(values.size() + 1);
  const hsize_t n = static_cast<hsize_t>(nrows);
  H5Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  H5Sselect_none(space);
  for (const Piece& p : pieces) {
    buf.insert(buf.end(), values.begin() + p.at, values.begin() + p.at + p.count);
    const hsize_t start = static_cast<hsize_t>(p.first), count = static_cast<hsize_t>(p.count);
    H5Sselect_hyperslab(space, H5S_SELECT_OR, &start, nullptr, &count, nullptr);
  }
  const hsize_t m = static_cast<hsize_t>(buf.size());
  buf.push_back(T()); // a valid pointer even when this rank writes nothing
  H5Handle ds(H5Dcreate2(file, ("/" + name).c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT,
                         H5P_DEFAULT),
              H5Dclose);
  const hsize_t one = 1;
  H5Handle mem(H5Screate_simple(1, m ? &m : &one, nullptr), H5Sclose);
  if (!space.ok() || !ds.ok() || !mem.ok()) return false;
  if (m == 0) H5Sselect_none(mem);
  return H5Dwrite(ds, mem_type, mem, space, dxpl, buf.data()) >= 0;
}

bool write_attribute(hid_t obj, const std::string& name, const std::string& value) {
  H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type, value.empty() ? 1 : value.size());
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  H5Handle a(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  return a.ok() && H5Awrite(a, type, value.c_str()) >= 0;
}

std::string read_string_attribute(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) return {};
  H5Handle a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  H5Handle type(a.ok() ? H5Aget_type(a) : -1, H5Tclose);
  if (!type.ok() || H5Tget_class(type) != H5T_STRING || H5Tis_variable_str(type) > 0) return {};
  std::string v(H5Tget_size(type), '\0');
  H5Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(mem, v.size());
  if (H5Aread(a, mem, v.data()) < 0) return {};
  return v.substr(0, v.find('\0'));
}

herr_t list_datasets(hid_t, const char* name, const H5L_info_t*, void* data) {
  static_cast<std::vector<std::string>*>(data)->push_back(name);
  return 0;
}

} // namespace

std::string read_h5_table(const std::string& path, std::vector<std::string>& columns,
                          std::vector<std::vector<double>>& values) {
  H5Silent quiet;
  if (H5Fis_hdf5(path.c_str()) <= 0) return "not an HDF5 file";
  H5Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) return "cannot open it";
  columns.clear();
  const std::string names = read_string_attribute(file, "columns");
  for (size_t pos = 0; !names.empty();) {
    const size_t c = names.find(',', pos);
    columns.push_back(names.substr(pos, c - pos));
    if (c == std::string::npos) break;
    pos = c + 1;
  }
  if (columns.empty())
    H5Literate(file, H5_INDEX_NAME, H5_ITER_INC, nullptr, list_datasets, &columns);
  if (columns.empty()) return "no datasets in its root group";
  values.assign(columns.size(), {});
  for (size_t c = 0; c < columns.size(); ++c) {
    const std::string ds_name = "/" + columns[c];
    H5Handle ds(H5Lexists(file, ds_name.c_str(), H5P_DEFAULT) > 0
                    ? H5Dopen2(file, ds_name.c_str(), H5P_DEFAULT)
                    : -1,
                H5Dclose);
    H5Handle space(ds.ok() ? H5Dget_space(ds) : -1, H5Sclose);
    H5Handle type(ds.ok() ? H5Dget_type(ds) : -1, H5Tclose);
    if (!space.ok() || H5Sget_simple_extent_ndims(space) != 1 ||
        (H5Tget_class(type) != H5T_FLOAT && H5Tget_class(type) != H5T_INTEGER))
      return "no 1-D numeric dataset " + ds_name;
    values[c].resize(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
    if (values[c].size() != values[0].size())
      return ds_name + " has " + std::to_string(values[c].size()) + " values, /" + columns[0] +
             " " + std::to_string(values[0].size());
    if (!values[c].empty() &&
        H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values[c].data()) < 0)
      return "cannot read " + ds_name;
  }
  return {};
}

std::string write_h5_table(MPI_Comm comm, const std::string& path, long long nrows,
                           const H5TableData& d,
                           const std::vector<std::pair<std::string, std::string>>& attributes) {
  H5Silent quiet;
  namespace fs = std::filesystem;
  const std::string tmp =
      (fs::path(path).parent_path() / ("." + fs::path(path).filename().string() + ".tmp")).string();
  const std::vector<Piece> pieces = sorted_pieces(d);
  int failed = 0;
  {
    H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
    H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
    H5Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose);
    H5Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
    H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE);
    if (!file.ok()) return "cannot write " + tmp; // collective: every rank fails alike
    for (size_t c = 0; c < d.int_names.size(); ++c)
      failed |= !write_column(file, dxpl, d.int_names[c], H5T_STD_I64LE, H5T_NATIVE_LLONG, nrows,
                              d.ints[c], pieces);
    for (size_t c = 0; c < d.real_names.size(); ++c)
      failed |= !write_column(file, dxpl, d.real_names[c], H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, nrows,
                              d.reals[c], pieces);
    for (const auto& [name, value] : attributes) // metadata: the same call on every rank
      failed |= !write_attribute(file, name, value);
  }
  MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, comm);
  if (failed) return "cannot write " + tmp + " (HDF5 / MPI-IO error)";
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::error_code ec;
  if (rank == 0) fs::rename(tmp, path, ec);
  int bad = ec ? 1 : 0;
  MPI_Bcast(&bad, 1, MPI_INT, 0, comm);
  return bad ? "cannot rename " + tmp + " to " + path : std::string();
}

} // namespace morphogen::io
