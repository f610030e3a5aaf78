// Test helpers: build a Simulation from option pairs on a given communicator, and gather a
// whole distributed field onto rank 0 of that communicator.
#pragma once

#include "app/simulation.hpp"
#include "io/slice_gather.hpp"

#include <memory>
#include <utility>
#include <vector>

namespace morphogen::testing {

using OptionList = std::vector<std::pair<std::string, std::string>>;

inline void set_options(const OptionList& opts) {
  PetscOptionsClear(nullptr);
  for (const auto& [k, v] : opts)
    PetscOptionsSetValue(nullptr, ("-" + k).c_str(), v.c_str());
}

inline std::unique_ptr<Simulation> make_sim(MPI_Comm comm, const OptionList& opts) {
  set_options(opts);
  Options opt(comm);
  return std::make_unique<Simulation>(comm, opt, "");
}

// All cells of a ghosted local array (x fastest, then y, then z) on rank 0; empty elsewhere.
inline std::vector<double> gather_all(const Grid& grid, Vec local) {
  const PetscScalar* a;
  VecGetArrayRead(local, &a);
  std::vector<double> all;
  for (PetscInt k = 0; k < grid.spec().n[2]; ++k) {
    auto s = io::gather_xy_slice(grid, a, k);
    all.insert(all.end(), s.begin(), s.end());
  }
  VecRestoreArrayRead(local, &a);
  return all;
}

} // namespace morphogen::testing
