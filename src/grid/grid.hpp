// Structured grid: one DMDA (dof = 1) in 2-D or 3-D, cell-centred.
//
// Axis d has n[d] cells of width h[d] = L[d] / n[d]; cell i has centre x = (i + 1/2) h.
// Boundaries per axis: periodic (DM_BOUNDARY_PERIODIC) or zero-flux / Dirichlet
// (DM_BOUNDARY_GHOSTED: PETSc allocates the ghost layer, morphogen fills it, see halo.hpp).
// Every species and parameter field is its own Vec on this DMDA (structure of arrays). Local
// (ghosted) arrays are addressed with x fastest: idx = (i-gxs) + gxm*((j-gys) + gym*(k-gzs)).
#pragma once

#include "core/petsc_handle.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <vector>

namespace morphogen {

enum class Boundary { Periodic, Neumann, Dirichlet };

const char* boundary_name(Boundary b);

struct GridSpec {
  int dim = 2;
  std::array<PetscInt, 3> n{1, 1, 1};
  std::array<double, 3> L{1, 1, 1};
  std::array<Boundary, 3> bc{Boundary::Periodic, Boundary::Periodic, Boundary::Periodic};
  int stencil_width = 1;
  bool box_stencil = true; // ghost corners are needed by the 9-point stencil
  // Optional cells per process along each axis (empty: PETSc decides). Grid sequencing sets
  // them to twice the coarser level's, so each fine cell's coarse parents are local.
  std::array<std::vector<PetscInt>, 3> ranges{};
  double h(int d) const { return L[d] / static_cast<double>(n[d]); }
};

struct Box {
  PetscInt s[3]{0, 0, 0}; // first index per axis
  PetscInt m[3]{1, 1, 1}; // extent per axis
  PetscInt size() const { return m[0] * m[1] * m[2]; }
  bool contains(PetscInt i, PetscInt j, PetscInt k) const {
    return i >= s[0] && i < s[0] + m[0] && j >= s[1] && j < s[1] + m[1] && k >= s[2] &&
           k < s[2] + m[2];
  }
};

class Grid {
public:
  Grid(MPI_Comm comm, const GridSpec& spec);

  const GridSpec& spec() const { return spec_; }
  int dim() const { return spec_.dim; }
  DM dm() const { return dm_; }
  MPI_Comm comm() const;
  const Box& owned() const { return owned_; }
  const Box& ghosted() const { return ghosted_; }
  PetscInt global_cells() const { return spec_.n[0] * spec_.n[1] * spec_.n[2]; }

  // Index of global cell (i,j,k) in this rank's ghosted local array.
  PetscInt local_index(PetscInt i, PetscInt j, PetscInt k) const {
    return (i - ghosted_.s[0]) +
           ghosted_.m[0] * ((j - ghosted_.s[1]) + ghosted_.m[1] * (k - ghosted_.s[2]));
  }
  // Index of global cell (i,j,k) in this rank's owned (global-Vec) array.
  PetscInt owned_index(PetscInt i, PetscInt j, PetscInt k) const {
    return (i - owned_.s[0]) + owned_.m[0] * ((j - owned_.s[1]) + owned_.m[1] * (k - owned_.s[2]));
  }
  // Natural (rank-independent) linear index of a global cell.
  std::uint64_t natural_index(PetscInt i, PetscInt j, PetscInt k) const {
    return static_cast<std::uint64_t>(i) +
           static_cast<std::uint64_t>(spec_.n[0]) *
               (static_cast<std::uint64_t>(j) +
                static_cast<std::uint64_t>(spec_.n[1]) * static_cast<std::uint64_t>(k));
  }
  double centre(int d, PetscInt i) const { return (static_cast<double>(i) + 0.5) * spec_.h(d); }

  VecH create_local() const;
  // Cells per process along each axis (what GridSpec::ranges would reproduce).
  std::array<std::vector<PetscInt>, 3> ownership_ranges() const;
  // Per axis: each process's first index and count (axes beyond dim(): one process, 1 cell),
  // and the owner of an index.
  struct AxisRanges {
    std::vector<PetscInt> start, count;
    PetscInt owner(PetscInt i) const {
      const auto it = std::upper_bound(start.begin(), start.end(), i);
      return static_cast<PetscInt>(it - start.begin()) - 1;
    }
  };
  std::array<AxisRanges, 3> axis_ranges() const;
  VecH create_global() const;

private:
  GridSpec spec_;
  DMH dm_;
  Box owned_, ghosted_;
};

} // namespace morphogen
