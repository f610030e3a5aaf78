#include "integrators/fused_sweep.hpp"

#include "core/log_events.hpp"
#include "grid/wide_halo.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace morphogen {

int FusedSweep::radius(const RowStencil& rows) {
  int r = 1;
  for (int q = 0; q < rows.nrows; ++q)
    r = std::max(r, std::abs(rows.off[q][0]));
  return r;
}

FusedSweep::FusedSweep(const Grid& grid, const RowStencil& rows, int nspecies, int depth)
    : grid_(grid), rows_(rows), ns_(nspecies), depth_(depth), r_(radius(rows)),
      frame_(grid, depth * radius(rows)), ring_(2 * radius(rows) + 1) {
  // Rows padded to whole cache lines, plus one line against cache-set aliasing of the ring.
  stride_ = (frame_.lx() + 7) / 8 * 8 + 8;
  frame_buf_.assign(static_cast<size_t>(ns_), std::vector<double>(frame_.size()));
  ring_buf_.assign(static_cast<size_t>(depth_ * ns_ * ring_ * stride_), 0.0);
  in0_.assign(static_cast<size_t>(ns_), std::vector<const double*>(ring_, nullptr));
}

void FusedSweep::set_params(const ParamSet& params) {
  const size_t np = params.scalar.size();
  pwide_.assign(np, {});
  pfield_.assign(np, false);
  const Box& ob = grid_.owned();
  WideHalo wide(grid_, frame_.width()); // periodic: the box is owned +- W, Lx by Ly
  VecH local = grid_.create_local();
  for (size_t q = 0; q < np; ++q) {
    if (!params.field[q].get()) {
      pwide_[q].assign(static_cast<size_t>(frame_.lx()), params.scalar[q]);
      continue;
    }
    pfield_[q] = true;
    const PetscScalar* f;
    PetscScalar* l;
    MG_PETSC(VecGetArrayRead(params.field[q], &f));
    MG_PETSC(VecGetArray(local, &l));
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      std::memcpy(l + grid_.local_index(ob.s[0], j, 0), f + grid_.owned_index(ob.s[0], j, 0),
                  sizeof(double) * ob.m[0]);
    pwide_[q].resize(static_cast<size_t>(wide.size()));
    wide.fill(l, pwide_[q].data());
    MG_PETSC(VecRestoreArray(local, &l));
    MG_PETSC(VecRestoreArrayRead(params.field[q], &f));
  }
}

// Row jw of the input box: the frame's row itself outside the owned rows, else left strip,
// owned row and right strip copied into the level-0 ring.
const double* FusedSweep::input_row(const std::vector<const double*>& in, int s,
                                    PetscInt jw) const {
  const double* f = frame_buf_[s].data() + frame_.row_offset(jw);
  if (!frame_.owned_row(jw)) return f;
  const Box& ob = grid_.owned();
  const PetscInt W = frame_.width(), mx = ob.m[0];
  double* row = ring_row(0, s, jw);
  const double* own = in[s] + grid_.local_index(ob.s[0], ob.s[1] - W + jw, 0);
  std::memcpy(row, f, sizeof(double) * W);
  std::memcpy(row + W, own, sizeof(double) * mx);
  std::memcpy(row + W + mx, f + W, sizeof(double) * W);
  return row;
}

void FusedSweep::run(const std::vector<const double*>& in, const std::vector<double*>& out, int n,
                     ExplicitRow row, RowFn fn) const {
  {
    LogScope log_scope(log_events().halo);
    std::vector<double*> f(ns_);
    for (int s = 0; s < ns_; ++s)
      f[s] = frame_buf_[s].data();
    frame_.fill(in, f);
  }
  LogScope log_scope(log_events().sweep);
  const Box& ob = grid_.owned();
  const PetscInt W = frame_.width(), lx = frame_.lx(), ly = frame_.ly();
  const int nr = rows_.nrows;
  std::vector<const double*> src(static_cast<size_t>(ns_ * nr));
  std::vector<double*> dst(ns_);
  std::vector<size_t> slot(static_cast<size_t>(nr));
  const size_t np = pwide_.size();
  std::vector<const double*> prow(np);
  row.prow = prow.data();
  row.src = src.data();
  row.dst = dst.data();
  row.wclass = nullptr;
  auto margin = [&](int l) { return W - static_cast<PetscInt>(n - l) * r_; };
  const PetscInt e0 = margin(0);
  for (PetscInt jw = e0; jw < ly - e0; ++jw) {
    for (int s = 0; s < ns_; ++s)
      in0_[s][jw % ring_] = input_row(in, s, jw);
    for (int l = 1; l <= n; ++l) {
      const PetscInt jl = jw - static_cast<PetscInt>(l) * r_, e = margin(l);
      if (jl < e || jl >= ly - e) continue;
      for (int q = 0; q < nr; ++q) // ring slot of each stencil row (one modulo per row)
        slot[q] = static_cast<size_t>((jl + rows_.off[q][0]) % ring_);
      for (int s = 0; s < ns_; ++s) {
        const double* base = l == 1 ? nullptr : ring_row(l - 1, s, 0);
        for (int q = 0; q < nr; ++q)
          src[s * nr + q] =
              (l == 1 ? in0_[s][slot[q]] : base + slot[q] * static_cast<size_t>(stride_)) + e;
        dst[s] = l < n ? ring_row(l, s, jl) + e
                       : out[s] + grid_.local_index(ob.s[0], ob.s[1] - W + jl, 0);
      }
      for (size_t q = 0; q < np; ++q)
        prow[q] = pwide_[q].data() + (pfield_[q] ? jl * lx : 0) + e;
      row.n = static_cast<int>(lx - 2 * e);
      fn(row);
    }
  }
}

} // namespace morphogen
