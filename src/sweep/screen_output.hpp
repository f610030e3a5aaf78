// Output of a Turing screen (`morphogen screen`, sweep/screen_main.hpp):
//
//   DIR/turing_sets.csv  one row per Turing-unstable set, in index order:
//                        index,<varied quantities...>,wavelength,k,growth,u_<species>...
//                        (wavelength = 2 pi / k in the model's length units, growth in 1/time,
//                        u the steady state analysed; numbers in shortest round-trip form)
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
  std::string text;              // this rank's rows, chunk after chunk
  std::vector<long long> chunks; // the chunk numbers, in the order of `text`
  std::vector<long long> sizes;  // bytes of each chunk's rows
  // Appends the row of Turing-unstable set `index` (values: the varied quantities).
  void add(long long index, const std::vector<double>& values, const SetResult& r);
  // Ends the current chunk (call once per chunk, after its rows).
  void end_chunk(long long chunk);

private:
  long long ended_ = 0; // text.size() at the last end_chunk
};

// Collective: writes header + every rank's rows in chunk order to path (nchunks chunks in all).
// Returns "" or the (same on every rank) error message.
std::string write_screen_csv(MPI_Comm comm, const std::string& path, const std::string& header,
                             const ScreenRows& rows, long long nchunks);

} // namespace morphogen::sweep
