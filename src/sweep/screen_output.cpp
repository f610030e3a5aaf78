// Output of a Turing screen: see screen_output.hpp.
#include "sweep/screen_output.hpp"

#include "io/h5_table.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>

namespace morphogen::sweep {

namespace {

void put(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

void put(std::string& s, long long v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}

// The error of the lowest rank that has one, on every rank ("" if none).
std::string agree(MPI_Comm comm, const std::string& err) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int who = err.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &who, 1, MPI_INT, MPI_MIN, comm);
  if (who == size) return "";
  int len = rank == who ? static_cast<int>(err.size()) : 0;
  MPI_Bcast(&len, 1, MPI_INT, who, comm);
  std::string msg = rank == who ? err : std::string(static_cast<size_t>(len), ' ');
  MPI_Bcast(msg.data(), len, MPI_CHAR, who, comm);
  return msg;
}

// Offset of every chunk in the file (from `header` on), from all ranks' chunk sizes (bytes or
// rows; sizes[c] is that of this rank's chunk chunks[c]).
std::vector<long long> chunk_offsets(MPI_Comm comm, const std::vector<long long>& chunks,
                                     const std::vector<long long>& sizes, long long nchunks,
                                     long long header) {
  std::vector<long long> size(static_cast<size_t>(nchunks), 0);
  for (size_t c = 0; c < chunks.size(); ++c)
    size[static_cast<size_t>(chunks[c])] = sizes[c];
  // Each chunk belongs to one rank; the sum over ranks assembles the table.
  MPI_Allreduce(MPI_IN_PLACE, size.data(), static_cast<int>(nchunks), MPI_LONG_LONG, MPI_SUM, comm);
  std::vector<long long> off(static_cast<size_t>(nchunks));
  long long at = header;
  for (long long c = 0; c < nchunks; ++c) {
    off[static_cast<size_t>(c)] = at;
    at += size[static_cast<size_t>(c)];
  }
  return off;
}

// Writes n bytes at offset in pieces below 1 GiB (MPI counts are int).
bool write_at(MPI_File fh, long long offset, const char* data, long long n) {
  constexpr long long kPiece = 1LL << 30;
  for (long long done = 0; done < n; done += kPiece) {
    const int len = static_cast<int>(std::min(kPiece, n - done));
    if (MPI_File_write_at(fh, offset + done, data + done, len, MPI_CHAR, MPI_STATUS_IGNORE) !=
        MPI_SUCCESS)
      return false;
  }
  return true;
}

} // namespace

std::string screen_csv_header(const std::vector<std::string>& varied,
                              const std::vector<std::string>& species) {
  std::string h = "index";
  for (const auto& v : varied)
    h += "," + v;
  h += ",wavelength,k,growth";
  for (const auto& s : species)
    h += ",u_" + s;
  return h + "\n";
}

void ScreenRows::add(long long set, const std::vector<double>& values, const SetResult& r) {
  std::vector<double> row = values;
  row.insert(row.end(), {r.wavelength, r.k, r.growth});
  row.insert(row.end(), r.u.begin(), r.u.end());
  ++rows_;
  if (numbers) {
    index.push_back(set);
    columns.resize(row.size());
    for (size_t c = 0; c < row.size(); ++c)
      columns[c].push_back(row[c]);
  }
  if (!csv) return;
  put(text, set);
  for (double v : row)
    text += ',', put(text, v);
  text += '\n';
}

void ScreenRows::end_chunk(long long chunk) {
  chunks.push_back(chunk);
  sizes.push_back(static_cast<long long>(text.size()) - ended_);
  counts.push_back(rows_ - rows_ended_);
  ended_ = static_cast<long long>(text.size());
  rows_ended_ = rows_;
}

std::string write_screen_h5(MPI_Comm comm, const std::string& path,
                            const std::vector<std::string>& columns, const ScreenRows& rows,
                            long long nchunks, const std::string& model) {
  const auto first = chunk_offsets(comm, rows.chunks, rows.counts, nchunks, 0);
  long long total = 0;
  for (long long c : rows.counts)
    total += c;
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_LONG_LONG, MPI_SUM, comm);
  io::H5TableData d;
  d.int_names = {"index"};
  d.ints = {rows.index};
  d.real_names = columns;
  d.reals = rows.columns;
  d.reals.resize(columns.size());
  for (size_t c = 0; c < rows.chunks.size(); ++c)
    d.pieces.emplace_back(first[static_cast<size_t>(rows.chunks[c])], rows.counts[c]);
  std::string names = "index";
  for (const auto& c : columns)
    names += "," + c;
  return io::write_h5_table(comm, path, total, d, {{"model", model}, {"columns", names}});
}

std::string write_screen_csv(MPI_Comm comm, const std::string& path, const std::string& header,
                             const ScreenRows& rows, long long nchunks) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::string tmp = (std::filesystem::path(path).parent_path() /
                           ("." + std::filesystem::path(path).filename().string() + ".tmp"))
                              .string();
  const auto off =
      chunk_offsets(comm, rows.chunks, rows.sizes, nchunks, static_cast<long long>(header.size()));
  if (rank == 0) std::remove(tmp.c_str()); // no stale tail from a longer earlier file
  MPI_Barrier(comm);
  MPI_File fh;
  std::string err;
  if (MPI_File_open(comm, tmp.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY, MPI_INFO_NULL, &fh) !=
      MPI_SUCCESS)
    return "cannot write " + tmp; // MPI_File_open is collective: every rank fails alike
  bool ok = rank != 0 || write_at(fh, 0, header.data(), static_cast<long long>(header.size()));
  long long at = 0;
  for (size_t c = 0; c < rows.chunks.size() && ok; ++c) {
    ok = write_at(fh, off[static_cast<size_t>(rows.chunks[c])], rows.text.data() + at,
                  rows.sizes[c]);
    at += rows.sizes[c];
  }
  MPI_File_close(&fh);
  if (!ok) err = "cannot write " + tmp;
  err = agree(comm, err);
  if (err.empty() && rank == 0) {
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) err = "cannot rename " + tmp + " to " + path + " (" + ec.message() + ")";
  }
  return agree(comm, err);
}

} // namespace morphogen::sweep
