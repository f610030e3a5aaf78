// Output of a Turing screen (`morphogen screen`, sweep/screen_main.hpp):
//
//   DIR/turing_sets.csv  one row per Turing-unstable set, in index order:
//                        index,<varied quantities...>,wavelength,k,growth,u_<species>...
//                        (wavelength = 2 pi / k in the model's length units, growth in 1/time,
//                        u the steady state analysed; numbers in shortest round-trip form)
//   DIR/turing_sets.h5   (-screen_format hdf5|both) the same table, one 1-D dataset per column:
//                        /index (int64), /<varied...>, /wavelength, /k, /growth, /u_<species>
//                        (float64); root attributes model and columns (the CSV header order)
//   DIR/screen.json      the setup, the counts and the timing (written by the caller)
//
// Rows are built per chunk of sets in memory (ScreenRows) and written collectively with MPI-IO
// at offsets from an all-gather of the chunk sizes, so chunks may be dealt to the ranks in any
// order and the file is the same on any rank count. The file is written as DIR/.turing_sets.csv
// .tmp and renamed when complete.
#pragma once

#include "sweep/screen_classify.hpp"

#include <mpi.h>

#include <string>
#include <vector>

namespace morphogen::sweep {

// The CSV header line (with its newline).
std::string screen_csv_header(const std::vector<std::string>& varied,
                              const std::vector<std::string>& species);

struct ScreenRows {
  bool csv = true, numbers = false;         // keep the rows as text (CSV) and/or as numbers (HDF5)
  std::string text;                         // this rank's rows, chunk after chunk
  std::vector<long long> chunks;            // the chunk numbers, in the order of `text`
  std::vector<long long> sizes;             // bytes of each chunk's rows
  std::vector<long long> counts;            // rows of each chunk
  std::vector<long long> index;             // numbers: each row's set index
  std::vector<std::vector<double>> columns; // numbers: the other columns, row after row
  // Appends the row of Turing-unstable set `index` (values: the varied quantities).
  void add(long long index, const std::vector<double>& values, const SetResult& r);
  // Ends the current chunk (call once per chunk, after its rows).
  void end_chunk(long long chunk);

private:
  long long ended_ = 0, rows_ = 0, rows_ended_ = 0; // at the last end_chunk
};

// Collective: writes header + every rank's rows in chunk order to path (nchunks chunks in all).
// Returns "" or the (same on every rank) error message.
std::string write_screen_csv(MPI_Comm comm, const std::string& path, const std::string& header,
                             const ScreenRows& rows, long long nchunks);

// Collective: writes every rank's rows as numbers (rows.numbers) to the HDF5 file `path`, in
// chunk order; columns: the header's names after index. Returns "" or the (same) error.
std::string write_screen_h5(MPI_Comm comm, const std::string& path,
                            const std::vector<std::string>& columns, const ScreenRows& rows,
                            long long nchunks, const std::string& model);

} // namespace morphogen::sweep
