#include "integrators/fused_sweep.hpp"

#include "core/log_events.hpp"
#include "core/prefetch.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace morphogen {

int FusedSweep::radius(const RowStencil& rows) {
  int r = 1;
  for (int q = 0; q < rows.nrows; ++q)
    r = std::max(r, std::abs(rows.off[q][0]));
  return r;
}

FusedSweep::FusedSweep(const Grid& grid, const RowStencil& rows, int nspecies, int depth,
                       PetscInt tile)
    : grid_(grid), rows_(rows), ns_(nspecies), depth_(depth), tile_(tile), r_(radius(rows)),
      frame_(grid, depth * radius(rows)), ring_(2 * radius(rows) + 1) {
  by_class_ = to_class_order(rows_, classes_); // 9pt: the kernel's fast form
  // Rows padded to whole cache lines, plus one line against cache-set aliasing of the ring.
  stride_ = (frame_.lx() + 7) / 8 * 8 + 8;
  frame_buf_.assign(static_cast<size_t>(ns_), std::vector<double>(frame_.size()));
  ring_buf_.assign(static_cast<size_t>(depth_ * ns_ * ring_ * stride_), 0.0);
  in0_.assign(static_cast<size_t>(ns_), std::vector<InputRow>(ring_));
}

void FusedSweep::set_params(const ParamSet& params) {
  const size_t np = params.scalar.size();
  params_ = &params;
  pwide_.assign(np, {});
  pfield_.assign(np, false);
  const FrameHalo frame(grid_, frame_.width(), FrameHalo::Source::Owned);
  for (size_t q = 0; q < np; ++q) {
    if (!params.field[q].get()) {
      pwide_[q].assign(static_cast<size_t>(frame_.lx()), params.scalar[q]);
      continue;
    }
    pfield_[q] = true;
    pwide_[q].resize(static_cast<size_t>(frame.size()));
    const PetscScalar* f;
    MG_PETSC(VecGetArrayRead(params.field[q], &f));
    frame.fill({f}, {pwide_[q].data()});
    MG_PETSC(VecRestoreArrayRead(params.field[q], &f));
  }
}

// The frame row (all columns of a frame row; on an owned row its left strip holds [0, W), its
// right strip [W + mx, Lx) from W on), else the owned row of f.
const double* FusedSweep::param_at(size_t q, const double* f, PetscInt jw, PetscInt x) const {
  const double* fr = pwide_[q].data() + frame_.row_offset(jw);
  const PetscInt W = frame_.width(), mx = grid_.owned().m[0];
  if (!frame_.owned_row(jw) || x < W) return fr + x;
  if (x >= W + mx) return fr + (x - mx);
  return f + (jw - W) * mx + (x - W);
}

// Row jw of the input box for step 1, as two bases indexed by box column x: `edge` for the
// columns within 2 cells of the strips, `mid` for the owned columns. Outside the owned rows both
// are the frame's row. An owned row is read in place (mid = the owned row, shifted by W); only
// the strips and the owned row's first and last two cells are copied into the level-0 ring
// (edge), so step 1's row splits into three calls (run). Narrow rows (mx < kInPlaceMin) are
// copied whole (edge = mid = the ring row).
FusedSweep::InputRow FusedSweep::input_row(const std::vector<const double*>& in, int s, PetscInt jw,
                                           const LeftStrip& left) const {
  const double* f = frame_buf_[s].data() + frame_.row_offset(jw);
  if (!frame_.owned_row(jw)) return {f, f};
  const Box& ob = grid_.owned();
  const PetscInt W = frame_.width(), mx = ob.m[0];
  double* row = ring_row(0, s, jw);
  const double* own = in[s] + grid_.local_index(ob.s[0], ob.s[1] - W + jw, 0);
  std::memcpy(row, f, sizeof(double) * W);
  std::memcpy(row + W + mx, f + W, sizeof(double) * W);
  const bool whole = mx < kInPlaceMin;
  if (whole) {
    std::memcpy(row + W, own, sizeof(double) * mx);
  } else {
    std::memcpy(row + W, own, sizeof(double) * 2);
    std::memcpy(row + W + mx - 2, own + mx - 2, sizeof(double) * 2);
  }
  if (left.c0 < left.t0) { // in place: the columns left of the tile as they were, its first two
    const PetscInt w = left.t0 - left.c0;
    std::memcpy(row + left.c0, left.data[s] + (jw - W) * w, sizeof(double) * w);
    const PetscInt live = std::min<PetscInt>(2, W + mx - left.t0);
    std::memcpy(row + left.t0, own + (left.t0 - W), sizeof(double) * live);
  }
  return whole ? InputRow{row, row} : InputRow{row, own - W};
}

// In place: the owned columns [max(t0 - n, W), t0) of every owned row (box coordinates), which
// the tiles left of t0 overwrite before the tile at t0 reads them.
FusedSweep::LeftStrip FusedSweep::save_left_strip(const std::vector<const double*>& in, int n,
                                                  PetscInt t0, size_t tile) const {
  const Box& ob = grid_.owned();
  const PetscInt W = frame_.width();
  LeftStrip left;
  left.t0 = t0;
  left.c0 = std::max<PetscInt>(t0 - n, W);
  const PetscInt w = t0 - left.c0;
  if (w <= 0) return left;
  if (strip_buf_.size() < (tile + 1) * ns_) strip_buf_.resize((tile + 1) * ns_);
  for (int s = 0; s < ns_; ++s) {
    std::vector<double>& buf = strip_buf_[tile * ns_ + s];
    buf.resize(static_cast<size_t>(w * ob.m[1]));
    for (PetscInt jo = 0; jo < ob.m[1]; ++jo)
      std::memcpy(buf.data() + jo * w,
                  in[s] + grid_.local_index(ob.s[0] + left.c0 - W, ob.s[1] + jo, 0),
                  sizeof(double) * w);
    left.data.push_back(buf.data());
  }
  return left;
}

// Columns per tile of a pass of n steps: the given width, else the widest whose ring rows
// (ring_ rows of the n levels the pass uses and ns_ species, its columns plus the 2 n r halo)
// stay within kTileBytes. A pass shorter than the depth the sweep was built for gets wider
// tiles (less halo recomputed); the results do not depend on the width.
PetscInt FusedSweep::tile_width(int n) const {
  if (tile_ > 0) return tile_;
  const double per_column = 8.0 * static_cast<double>(ring_ * n * ns_);
  const PetscInt fit = static_cast<PetscInt>(kTileBytes / per_column) - 2 * n * r_;
  return std::max<PetscInt>(kInPlaceMin, fit);
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
  const PetscInt W = frame_.width(), mx = grid_.owned().m[0];
  const PetscInt width = tile_width(n);
  const PetscInt tiles = std::max<PetscInt>(1, (mx + width - 1) / width);
  bool in_place = true;
  for (int s = 0; s < ns_; ++s)
    in_place = in_place && out[s] == in[s];
  if (in_place && n < 2)
    throw std::invalid_argument("FusedSweep::run: in place needs at least 2 steps per pass");
  auto start = [&](PetscInt t) { return W + t * mx / tiles; }; // box column of tile t
  std::vector<LeftStrip> left(static_cast<size_t>(tiles));     // all saved before any tile writes
  for (PetscInt t = 0; t < tiles; ++t)
    left[t] = in_place ? save_left_strip(in, n, start(t), static_cast<size_t>(t))
                       : LeftStrip{start(t), start(t), {}};
  std::vector<const double*> pf(pfield_.size(), nullptr);
  for (size_t q = 0; q < pf.size(); ++q)
    if (pfield_[q]) MG_PETSC(VecGetArrayRead(params_->field[q], &pf[q]));
  for (PetscInt t = 0; t < tiles; ++t)
    sweep_tile(in, out, n, row, fn, start(t), start(t + 1), left[t], pf);
  for (size_t q = 0; q < pf.size(); ++q)
    if (pfield_[q]) MG_PETSC(VecRestoreArrayRead(params_->field[q], &pf[q]));
}

// The owned box columns [t0, t1) (box coordinates): step l computes the columns
// [t0 - (n - l), t1 + (n - l)) of its rows (x taps reach one cell), step 1 reading box columns
// t0 - n .. t1 + n - 1 of the input rows.
void FusedSweep::sweep_tile(const std::vector<const double*>& in, const std::vector<double*>& out,
                            int n, ExplicitRow row, RowFn fn, PetscInt t0, PetscInt t1,
                            const LeftStrip& left, const std::vector<const double*>& pf) const {
  const Box& ob = grid_.owned();
  const PetscInt W = frame_.width(), ly = frame_.ly(), mx = ob.m[0];
  const int nr = rows_.nrows;
  std::vector<const double*> src(static_cast<size_t>(ns_ * nr));
  std::vector<double*> dst(ns_);
  std::vector<size_t> slot(static_cast<size_t>(nr));
  const size_t np = pwide_.size();
  const bool any_field = std::find(pfield_.begin(), pfield_.end(), true) != pfield_.end();
  std::vector<const double*> prow(np);
  row.prow = prow.data();
  row.src = src.data();
  row.dst = dst.data();
  row.wclass = by_class_ ? classes_.w.data() : nullptr;
  auto margin = [&](int l) { return W - static_cast<PetscInt>(n - l) * r_; };
  // Box columns [x0, x1) of row jl of step l; step 1 reads the input rows' `edge` or `mid` base.
  auto sweep_piece = [&](int l, PetscInt jl, PetscInt x0, PetscInt x1, bool mid) {
    if (x1 <= x0) return;
    for (int s = 0; s < ns_; ++s) {
      const double* base = l == 1 ? nullptr : ring_row(l - 1, s, 0);
      for (int q = 0; q < nr; ++q) {
        const InputRow& in0 = in0_[s][slot[q]];
        src[s * nr + q] =
            (l == 1 ? (mid ? in0.mid : in0.edge) : base + slot[q] * static_cast<size_t>(stride_)) +
            x0;
      }
      dst[s] = (l < n ? ring_row(l, s, jl)
                      : out[s] + grid_.local_index(ob.s[0], ob.s[1] - W + jl, 0) - W) +
               x0;
    }
    for (size_t q = 0; q < np; ++q)
      prow[q] = pfield_[q] ? param_at(q, pf[q], jl, x0) : pwide_[q].data() + x0;
    row.n = static_cast<int>(x1 - x0);
    fn(row);
  };
  // The same, split where the parameter fields' rows change base (the owned columns' edges).
  auto sweep_row = [&](int l, PetscInt jl, PetscInt x0, PetscInt x1, bool mid) {
    if (!any_field || !frame_.owned_row(jl)) return sweep_piece(l, jl, x0, x1, mid);
    const PetscInt a = std::clamp(W, x0, x1), b = std::clamp(W + mx, a, x1);
    sweep_piece(l, jl, x0, a, mid);
    sweep_piece(l, jl, a, b, mid);
    sweep_piece(l, jl, b, x1, mid);
  };
  const PetscInt e0 = margin(0);
  // Input row jw + kPrefetchRows of the tile's columns, a part per level (the owned rows are
  // read from memory; the prefetches spread over the levels' arithmetic).
  const PetscInt pc0 = std::max(t0 - n, W), pc1 = std::min(t1 + n, W + mx);
  auto prefetch_part = [&](PetscInt jw, int l) {
    const PetscInt jp = jw + kPrefetchRows;
    if (!frame_.owned_row(jp)) return;
    const PetscInt len = pc1 - pc0, c0 = pc0 + len * (l - 1) / n, c1 = pc0 + len * l / n;
    for (int s = 0; s < ns_; ++s)
      prefetch_doubles(in[s] + grid_.local_index(ob.s[0] + c0 - W, ob.s[1] - W + jp, 0), c1 - c0);
  };
  for (PetscInt jw = e0; jw < ly - e0; ++jw) {
    for (int s = 0; s < ns_; ++s)
      in0_[s][jw % ring_] = input_row(in, s, jw, left);
    for (int l = 1; l <= n; ++l) {
      prefetch_part(jw, l);
      const PetscInt jl = jw - static_cast<PetscInt>(l) * r_, e = margin(l);
      if (jl < e || jl >= ly - e) continue;
      for (int q = 0; q < nr; ++q) // ring slot of each stencil row (one modulo per row)
        slot[q] = static_cast<size_t>((jl + rows_.off[q][0]) % ring_);
      const PetscInt a = t0 - (n - l), b = t1 + (n - l);
      if (l > 1 || mx < kInPlaceMin) {
        sweep_row(l, jl, a, b, false);
        continue;
      }
      // Step 1: the owned row in place between its second (in place: the tile's second) and
      // second-last cell.
      const PetscInt lo = left.c0 < left.t0 ? left.t0 + 1 : W + 1;
      const PetscInt m0 = std::clamp(lo, a, b), m1 = std::clamp(W + mx - 1, m0, b);
      sweep_row(1, jl, a, m0, false);
      sweep_row(1, jl, m0, m1, true);
      sweep_row(1, jl, m1, b, false);
    }
  }
}

} // namespace morphogen
