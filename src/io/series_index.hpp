// Time-series indexes over a run's snapshot files, rewritten (temporary name, then rename) after
// every snapshot so a killed run always leaves valid indexes:
//
//   <name>.vtkhdf.series  JSON {"file-series-version": "1.0", "files": [{"name", "time"}...]},
//                         ParaView's file-series reader over the VTKHDF files;
//   <name>.xmf            XDMF 3 temporal collection of 3DCoRectMesh grids of the cell
//                         corners (Dimensions "nz+1 ny+1 nx+1", "1 ny+1 nx+1" in 2-D; origin 0,
//                         spacing h) whose Center="Cell" attributes point at the same HDF5
//                         datasets (<file>:/VTKHDF/PointData/<species>, shape "nz ny nx";
//                         files of the CellData layout: /VTKHDF/CellData/<species>). The values
//                         are cell data and the bounds are the domain, [0, n h] per axis (the
//                         .vtkhdf files themselves show them as points at the cell centres).
//
// Entries are keyed by step: re-adding a step replaces it, and a restart from step S drops the
// entries after S, so the series never holds duplicates.
#pragma once

#include "io/vtkhdf_file.hpp"

#include <string>
#include <vector>

namespace morphogen::io {

struct SeriesEntry {
  std::string file; // name relative to the output directory
  long long step = 0;
  double time = 0;
  ImageInfo info;
};

class SeriesIndex {
public:
  SeriesIndex(std::string dir, std::string name);

  // Re-reads an existing <name>.vtkhdf.series, keeping entries with step <= max_step whose file
  // is still a readable snapshot. Returns the number of entries kept.
  size_t load_existing(long long max_step);
  void add(SeriesEntry entry);
  // Writes both index files. Returns "" or the error.
  std::string write() const;

  const std::vector<SeriesEntry>& entries() const { return entries_; }
  std::string series_path() const { return dir_ + "/" + name_ + ".vtkhdf.series"; }
  std::string xmf_path() const { return dir_ + "/" + name_ + ".xmf"; }

private:
  std::string dir_, name_;
  std::vector<SeriesEntry> entries_;
};

// Writes `text` to `path` via a temporary file (unique to this host and process) and rename.
// Returns "" or the error.
std::string write_file_atomically(const std::string& path, const std::string& text);

} // namespace morphogen::io
