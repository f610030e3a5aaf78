// Temporal blocking of the explicit fast path (2-D, periodic axes): n <= k forward-Euler steps
// in one pass over the grid,
//   u^{m+1} = max( u^m + dt (D L u^m + R(u^m; p)), floor ),   m = 0 .. n-1,
// each cell of each step computed by the model's fused row kernel (explicit_kernel.hpp) from
// the same neighbours as a single step, so the result is bitwise that of n single steps.
//
// Halo: a frame k r cells wide (grid/frame_halo.hpp, r the stencil radius) filled once per
// call; the owned cells are read in place. Box rows jw = 0 .. Ly-1 and columns iw = 0 .. Lx-1
// (the owned box grown by W = k r). Step l (1..n) computes the box shrunk by
// e_l = W - (n - l) r on each side, so step n yields exactly the owned box. Wavefront along y:
// after input row jw is ready (strips from the frame, the owned row read in place), step l computes
// its row jw - l r, whose neighbours rows jw - l r +- r of step l - 1 are ready. Each step keeps a
// ring of 2r + 1 rows per species (2r + 1 rows of Lx cells per step and species stay in cache); the
// last step writes the owned row of the output arrays. Memory traffic per n steps: one read
// and one write of the state, instead of n of each; the owned input rows kPrefetchRows ahead
// are prefetched, a part per level. The 9pt stencil runs in its weight-class form (rows in
// class order, ExplicitRow::wclass), as the single steps do, so the ring rows, which share one
// alignment, are read as whole aligned vectors.
// In place (out == in): step n writes row j of a tile only after step 1 has read it for the last
// time (n >= 2), so only the columns a tile reads left of its own, which the tiles before it have
// overwritten, are saved: per tile after the first, its n columns left of it of every owned row,
// copied once at the start of the pass (no second state set).
// Per-cell parameters (field mode): each field's frame is filled once (set_params; the fields must
// not change afterwards) and each scalar copied into a row of Lx values (read only by kernels
// that take every parameter as a row). A step reads a field's row where it lies: a frame row,
// or on an owned row the frame's strips and the field's own vector, a row call split at the
// owned columns' edges (no copy of a field, per pass or over the box).
#pragma once

#include "fields/param_set.hpp"
#include "grid/frame_halo.hpp"
#include "grid/stencil.hpp"
#include "integrators/explicit_kernel.hpp"

#include <vector>

namespace morphogen {

class FusedSweep {
public:
  using RowFn = void (*)(const ExplicitRow&);
  // Up to `depth` >= 1 steps per call of `nspecies` species with the 2-D row stencil `rows`
  // (one grid row per y offset rows.off[q][0]). Collective (builds the frame halo).
  // tile: owned columns per tile (0: auto, ring rows within kTileBytes; see run).
  FusedSweep(const Grid& grid, const RowStencil& rows, int nspecies, int depth, PetscInt tile = 0);

  // Field mode: the parameters (fields fixed in time; `params` must outlive the sweep). Collective.
  void set_params(const ParamSet& params);

  // The stencil radius along y (x taps always reach 1 cell).
  static int radius(const RowStencil& rows);
  int depth() const { return depth_; }

  // n steps (1 <= n <= depth): in[s], out[s] ghosted local arrays of species s (owned cells of
  // `in` current; the owned cells of `out` written; out[s] == in[s] for every s: in place).
  // `row` carries w, D, floor, pconst and dt; src, dst and n are set here. Collective.
  void run(const std::vector<const double*>& in, const std::vector<double*>& out, int n,
           ExplicitRow row, RowFn fn) const;

private:
  double* ring_row(int level, int s, PetscInt jw) const {
    const size_t slot = static_cast<size_t>(jw % ring_);
    return ring_buf_.data() + ((static_cast<size_t>(level) * ns_ + s) * ring_ + slot) * stride_;
  }
  struct InputRow {
    const double* edge = nullptr; // box columns near the strips (or all of a frame row)
    const double* mid = nullptr;  // owned columns 1 .. mx - 2 (the owned row, read in place)
  };
  // Narrower owned rows are copied whole: one kernel call per row (at 64 cells three calls cost
  // more than the copy saves).
  static constexpr PetscInt kInPlaceMin = 512;
  // In place: the saved input columns [c0, t0) of every owned row for the tile starting at box
  // column t0 (data: per species, rows of t0 - c0 values), or none (c0 == t0).
  struct LeftStrip {
    PetscInt c0 = 0, t0 = 0;
    std::vector<const double*> data;
  };
  InputRow input_row(const std::vector<const double*>& in, int s, PetscInt jw,
                     const LeftStrip& left) const;
  // Row jw of parameter field q (owned values f) from box column x on, valid to the end of x's
  // piece: [0, W), [W, W + mx) or [W + mx, Lx) on an owned row, the whole row on a frame row.
  const double* param_at(size_t q, const double* f, PetscInt jw, PetscInt x) const;
  LeftStrip save_left_strip(const std::vector<const double*>& in, int n, PetscInt t0,
                            size_t tile) const;
  static constexpr PetscInt kPrefetchRows = 2; // input rows ahead of the wavefront prefetched
  static constexpr double kTileBytes = 1024.0 * 1024; // ring rows of one tile: half an L2
  PetscInt tile_width(int n) const;                   // owned columns per tile of a pass of n steps
  void sweep_tile(const std::vector<const double*>& in, const std::vector<double*>& out, int n,
                  ExplicitRow row, RowFn fn, PetscInt t0, PetscInt t1, const LeftStrip& left,
                  const std::vector<const double*>& pf) const;

  const Grid& grid_;
  RowStencil rows_;       // in class order where by_class_
  BoxClasses classes_;    // the box stencil's weights by class (9pt)
  bool by_class_ = false; // the kernel's weight-class form (ExplicitRow::wclass)
  int ns_, depth_;
  PetscInt tile_;
  int r_;
  FrameHalo frame_;
  PetscInt ring_;                                      // rows per ring: 2r + 1
  PetscInt stride_;                                    // doubles per ring row
  mutable std::vector<std::vector<double>> frame_buf_; // per species
  mutable std::vector<double> ring_buf_;               // [level][species][slot][stride]
  mutable std::vector<std::vector<InputRow>> in0_;     // level 0 rows per species and slot
  mutable std::vector<std::vector<double>> strip_buf_; // in place: per tile, saved left columns
  const ParamSet* params_ = nullptr;                   // field mode
  std::vector<std::vector<double>> pwide_; // per parameter: a scalar's row of Lx, a field's frame
  std::vector<bool> pfield_;               // parameter q is a field
};

} // namespace morphogen
