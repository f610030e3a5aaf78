#include "grid/halo.hpp"

#include <petscdmda.h>

#include <algorithm>
#include <cstring>

namespace morphogen {

namespace {

// Owner rank and owner's ghosted-box geometry along one axis.
struct AxisLayout {
  std::vector<PetscInt> start; // first owned index per process along the axis
  std::vector<PetscInt> count;
  PetscInt owner(PetscInt i) const {
    PetscInt p = 0;
    while (p + 1 < static_cast<PetscInt>(start.size()) && i >= start[p + 1])
      ++p;
    return p;
  }
};

} // namespace

Halo::Halo(const Grid& grid, bool x_wrap) : grid_(grid) {
  DM dm = grid.dm();
  const GridSpec& g = grid.spec();
  PetscInt P[3];
  MG_PETSC(DMDAGetInfo(dm, nullptr, nullptr, nullptr, nullptr, &P[0], &P[1], &P[2], nullptr,
                       nullptr, nullptr, nullptr, nullptr, nullptr));
  const PetscInt* lx[3] = {nullptr, nullptr, nullptr};
  MG_PETSC(DMDAGetOwnershipRanges(dm, &lx[0], &lx[1], &lx[2]));
  AxisLayout ax[3];
  const int sw = g.stencil_width;
  for (int d = 0; d < 3; ++d) {
    PetscInt s = 0;
    for (PetscInt p = 0; p < P[d]; ++p) {
      ax[d].start.push_back(s);
      ax[d].count.push_back(d < grid.dim() ? lx[d][p] : 1);
      s += d < grid.dim() ? lx[d][p] : 1;
    }
  }
  const Box& gb = grid.ghosted();
  const Box& ob = grid.owned();
  std::vector<PetscInt> leaves;
  std::vector<PetscSFNode> remotes;
  for (PetscInt k = gb.s[2]; k < gb.s[2] + gb.m[2]; ++k)
    for (PetscInt j = gb.s[1]; j < gb.s[1] + gb.m[1]; ++j)
      for (PetscInt i = gb.s[0]; i < gb.s[0] + gb.m[0]; ++i) {
        if (ob.contains(i, j, k) || (!x_wrap && (i < 0 || i >= g.n[0]))) continue;
        PetscInt c[3] = {i, j, k};
        bool inside = true;
        for (int d = 0; d < 3 && inside; ++d) {
          if (c[d] >= 0 && c[d] < g.n[d]) continue;
          if (g.bc[d] != Boundary::Periodic)
            inside = false;
          else
            c[d] = (c[d] % g.n[d] + g.n[d]) % g.n[d];
        }
        if (!inside) continue;
        PetscInt p[3], gs[3], gm[3];
        for (int d = 0; d < 3; ++d) {
          p[d] = ax[d].owner(c[d]);
          const bool has_ghost = d < grid.dim();
          gs[d] = ax[d].start[p[d]] - (has_ghost ? sw : 0);
          gm[d] = ax[d].count[p[d]] + (has_ghost ? 2 * sw : 0);
        }
        PetscSFNode r;
        r.rank = static_cast<PetscInt>(p[0] + P[0] * (p[1] + P[1] * p[2]));
        r.index = (c[0] - gs[0]) + gm[0] * ((c[1] - gs[1]) + gm[1] * (c[2] - gs[2]));
        leaves.push_back(grid.local_index(i, j, k));
        remotes.push_back(r);
      }
  MG_PETSC(PetscSFCreate(grid.comm(), sf_.out()));
  MG_PETSC(PetscSFSetGraph(sf_, gb.size(), static_cast<PetscInt>(leaves.size()), leaves.data(),
                           PETSC_COPY_VALUES, remotes.data(), PETSC_COPY_VALUES));
  MG_PETSC(PetscSFSetUp(sf_));
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  local_only_ = size == 1;
  if (local_only_) {
    std::vector<PetscInt> source;
    for (const PetscSFNode& r : remotes)
      source.push_back(r.index);
    split_runs(leaves, source);
  }
}

void Halo::split_runs(const std::vector<PetscInt>& ghost, const std::vector<PetscInt>& source) {
  const size_t n = ghost.size();
  std::vector<PetscInt> g, src; // not in a block run
  for (size_t q = 0; q < n;) {
    size_t e = q + 1;
    while (e < n && ghost[e] == ghost[e - 1] + 1 && source[e] == source[e - 1] + 1)
      ++e;
    const PetscInt len = static_cast<PetscInt>(e - q);
    if (len >= kMinRun) {
      runs_.push_back({ghost[q], source[q], len, 1});
    } else {
      g.insert(g.end(), ghost.begin() + q, ghost.begin() + e);
      src.insert(src.end(), source.begin() + q, source.begin() + e);
    }
    q = e;
  }
  split_strided(std::move(g), std::move(src));
}

// The ghosts of split_runs that are in no block run, grouped by their offset source - ghost
// and their ghosted column (ghost % gx: a ghost layer more than one cell wide is one run per
// column), ordered by position: arithmetic progressions of at least kMinRun become strided
// runs.
void Halo::split_strided(std::vector<PetscInt> ghost, std::vector<PetscInt> source) {
  std::vector<size_t> order(ghost.size());
  for (size_t q = 0; q < order.size(); ++q)
    order[q] = q;
  const PetscInt gx = grid_.ghosted().m[0];
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const PetscInt da = source[a] - ghost[a], db = source[b] - ghost[b];
    if (da != db) return da < db;
    const PetscInt ca = ghost[a] % gx, cb = ghost[b] % gx;
    return ca != cb ? ca < cb : ghost[a] < ghost[b];
  });
  auto same_run = [&](size_t a, size_t b, PetscInt stride) { // b follows a in a run
    return source[b] - ghost[b] == source[a] - ghost[a] && ghost[b] - ghost[a] == stride;
  };
  for (size_t q = 0; q < order.size();) {
    size_t e = q + 1;
    const PetscInt stride = e < order.size() ? ghost[order[e]] - ghost[order[q]] : 0;
    while (e < order.size() && same_run(order[e - 1], order[e], stride))
      ++e;
    const PetscInt len = static_cast<PetscInt>(e - q);
    if (len >= kMinRun) {
      strided_.push_back({ghost[order[q]], source[order[q]], len, stride});
      q = e;
      continue;
    }
    ghost_.push_back(ghost[order[q]]); // one by one; the next may start a run
    source_.push_back(source[order[q]]);
    ++q;
  }
}

void Halo::begin(double* a) const {
  if (local_only_) { // sources are owned cells: order does not matter
    for (const Run& r : runs_)
      std::memcpy(a + r.ghost, a + r.source, sizeof(double) * r.len);
    for (const Run& r : strided_) {
      double* __restrict__ g = a + r.ghost;
      const double* __restrict__ s = a + r.source;
      for (PetscInt q = 0, o = 0; q < r.len; ++q, o += r.stride)
        g[o] = s[o];
    }
    const PetscInt n = static_cast<PetscInt>(ghost_.size());
    const PetscInt* __restrict__ g = ghost_.data();
    const PetscInt* __restrict__ s = source_.data();
    for (PetscInt q = 0; q < n; ++q)
      a[g[q]] = a[s[q]];
    return;
  }
  MG_PETSC(PetscSFBcastBegin(sf_, MPIU_SCALAR, a, a, MPI_REPLACE));
}

void Halo::end(double* a) const {
  if (local_only_) return;
  MG_PETSC(PetscSFBcastEnd(sf_, MPIU_SCALAR, a, a, MPI_REPLACE));
}

PetscInt Halo::face_size(int d) const {
  const Box& gb = grid_.ghosted();
  const int a = d == 0 ? 1 : 0, b = d == 2 ? 1 : 2;
  return gb.m[a] * gb.m[b];
}

PetscInt Halo::face_index(int d, PetscInt i, PetscInt j, PetscInt k) const {
  const Box& gb = grid_.ghosted();
  const PetscInt c[3] = {i - gb.s[0], j - gb.s[1], k - gb.s[2]};
  const int a = d == 0 ? 1 : 0, b = d == 2 ? 1 : 2;
  return c[a] + gb.m[a] * c[b];
}

void Halo::fill_boundaries(double* u, const FaceValues* dirichlet, PetscInt stride) const {
  fill_faces(u, dirichlet, {1.0, 1.0, 1.0}, stride);
}

void Halo::fill_mirror(double* u, const std::array<double, 3>& sign) const {
  fill_faces(u, nullptr, sign, 1);
}

void Halo::fill_faces(double* u, const FaceValues* dirichlet, const std::array<double, 3>& sign,
                      PetscInt stride) const {
  const GridSpec& g = grid_.spec();
  const Box& gb = grid_.ghosted();
  const PetscInt str[3] = {1, gb.m[0], gb.m[0] * gb.m[1]};
  for (int d = 0; d < grid_.dim(); ++d) {
    if (g.bc[d] == Boundary::Periodic) continue;
    const bool dir = g.bc[d] == Boundary::Dirichlet && dirichlet;
    for (int side = 0; side < 2; ++side) {
      // Ghost layers beyond this face owned by this rank's ghost box.
      for (PetscInt layer = 1; layer <= g.stencil_width; ++layer) {
        const PetscInt ghost = side == 0 ? -layer : g.n[d] - 1 + layer;
        const PetscInt mirror = side == 0 ? layer - 1 : g.n[d] - layer; // reflected cell
        if (ghost < gb.s[d] || ghost >= gb.s[d] + gb.m[d]) continue;
        const std::vector<double>* vals = dir ? &dirichlet->face[2 * d + side] : nullptr;
        PetscInt lo[3] = {gb.s[0], gb.s[1], gb.s[2]}, hi[3];
        for (int e = 0; e < 3; ++e)
          hi[e] = gb.s[e] + gb.m[e];
        lo[d] = ghost;
        hi[d] = ghost + 1;
        for (PetscInt k = lo[2]; k < hi[2]; ++k)
          for (PetscInt j = lo[1]; j < hi[1]; ++j)
            for (PetscInt i = lo[0]; i < hi[0]; ++i) {
              const PetscInt gi = stride * grid_.local_index(i, j, k);
              const PetscInt mi = gi + stride * (mirror - ghost) * str[d];
              u[gi] = dir ? 2.0 * (*vals)[face_index(d, i, j, k)] - u[mi] : sign[d] * u[mi];
            }
      }
    }
  }
}

} // namespace morphogen
