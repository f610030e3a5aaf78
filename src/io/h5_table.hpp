// A table of named columns as an HDF5 file, written collectively: one 1-D dataset per column
// (/<name>, int64 for the integer columns, float64 for the real ones), nrows values each, plus
// string attributes on the root group. Each rank holds some pieces of the table (row ranges);
// every row is written by exactly one rank. The file is written as DIR/.<name>.tmp and renamed
// when complete, so a failed write leaves an earlier file intact.
#pragma once

#include <mpi.h>

#include <string>
#include <utility>
#include <vector>

namespace morphogen::io {

struct H5TableData {
  std::vector<std::string> int_names, real_names;
  // This rank's values, per column: its pieces' rows one after the other.
  std::vector<std::vector<long long>> ints;
  std::vector<std::vector<double>> reals;
  std::vector<std::pair<long long, long long>> pieces; // (first row, row count), in that order
};

// Collective. Returns "" or the message (the same on every rank).
std::string write_h5_table(MPI_Comm comm, const std::string& path, long long nrows,
                           const H5TableData& data,
                           const std::vector<std::pair<std::string, std::string>>& attributes);

// One rank: reads a table written by write_h5_table (or any HDF5 file of equally long 1-D
// numeric datasets in its root group): `columns` gets the root attribute "columns" split at
// commas when present, else the root datasets' names; values[c] the column's numbers. Returns ""
// or the reason ("not an HDF5 file", "no dataset /x", "/x has 3 values, /index 4", ...).
std::string read_h5_table(const std::string& path, std::vector<std::string>& columns,
                          std::vector<std::vector<double>>& values);

} // namespace morphogen::io
