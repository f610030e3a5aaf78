// The frame of a 2-D wide box: the cells of the owned box grown by W cells per axis that lie
// outside the owned box, filled from their owners through one PetscSF (the halo of W-step
// temporal blocking, integrators/fused_sweep.hpp; the owned cells are read in place).
//
// Both axes must be periodic: cell (i, j) of the box, in unwrapped global indices, holds the
// owner's value of cell (i mod nx, j mod ny), so W may exceed the neighbours' extent. Rows of
// the box are numbered jw = 0 .. Ly - 1 (Ly = my + 2W, global row s1 - W + jw), columns
// iw = 0 .. Lx - 1 (Lx = mx + 2W). The frame is stored row by row: a row outside the owned
// rows is stored whole (Lx cells, iw = 0 .. Lx - 1); an owned row stores its left strip
// (iw < W) then its right strip (iw >= W + mx), W cells each.
#pragma once

#include "grid/grid.hpp"

#include <vector>

namespace morphogen {

class FrameHalo {
public:
  // width W >= 1; the grid must be 2-D with both axes periodic. fill() reads the owners' ghosted
  // local arrays (Source::Ghosted) or their owned arrays (Source::Owned, e.g. a parameter field's
  // global vector). Collective.
  enum class Source { Ghosted, Owned };
  FrameHalo(const Grid& grid, int width, Source source = Source::Ghosted);

  int width() const { return width_; }
  PetscInt lx() const { return lx_; }
  PetscInt ly() const { return ly_; }
  PetscInt size() const { return size_; }
  // Start of row jw of the box in the frame array: the whole row when jw is outside the owned
  // rows, else the left strip (W cells) followed by the right strip (W cells).
  PetscInt row_offset(PetscInt jw) const { return offset_[static_cast<size_t>(jw)]; }
  bool owned_row(PetscInt jw) const { return jw >= width_ && jw < ly_ - width_; }
  // Fill the frame arrays f[s] (size() each) from the owned cells of the arrays local[s] (ghosted
  // or owned, as constructed) of every rank, all species' messages in flight together. Collective.
  void fill(const std::vector<const double*>& local, const std::vector<double*>& f) const;

private:
  int width_;
  PetscInt lx_ = 0, ly_ = 0, size_ = 0;
  std::vector<PetscInt> offset_;
  SFH sf_;
};

} // namespace morphogen
