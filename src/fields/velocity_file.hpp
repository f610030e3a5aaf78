// An advection velocity read from HDF5 files written by another code (or by morphogen's own
// snapshots), instead of the -velocity_x/_y expressions:
//   -velocity_file TEXT          one file (steady), a comma list or a .series JSON file
//                                (fields/velocity_series.hpp)
//   -velocity_datasets X,Y[,Z]   the component datasets, one per axis (default velocity_x,
//                                velocity_y[, velocity_z]: a bare name is found in
//                                /VTKHDF/PointData, /VTKHDF/CellData or /, see io/h5_arrays.hpp)
// In time: u(t) = (1 - w) u_k + w u_{k+1} between the bracketing frames t_k <= t < t_{k+1},
// w = (t - t_k) / (t_{k+1} - t_k); before the first frame and after the last the end frame is
// held (clamped, constant). Only the two bracketing frames are held in memory (owned cells of
// this rank, read block-wise through MPI-IO); a frame is read again when t passes it.
// At construction every frame is read once: values must be finite and max_abs() is the largest
// |u_d| over all frames (so over every t: an interpolation never exceeds its frames), which
// sizes the advection halo for the whole run. Bad input (missing file, not HDF5, missing
// dataset, wrong grid, non-finite value, times not increasing) is a one-line UserError naming
// the option and the value.
#pragma once

#include "fields/velocity_series.hpp"
#include "grid/grid.hpp"

#include <array>
#include <string>
#include <vector>

namespace morphogen {

class VelocityFile {
public:
  // `text`: the value of -velocity_file (already read). Reads -velocity_datasets. Collective.
  VelocityFile(const Grid& grid, Options& opt, const std::string& text,
               const std::string& base_dir);

  bool uses_time() const { return frames_.size() > 1; }
  // "-velocity_file TEXT" for messages.
  std::string option_text() const { return "-velocity_file " + text_; }
  // Largest |u_d| over every frame (0 beyond dim).
  const std::array<double, 3>& max_abs() const { return umax_; }
  // Component d at the owned cells (owned layout, x fastest) at time t. Collective when a new
  // frame has to be read.
  void owned(int d, double t, double* out);
  // One phrase for the run banner: files, frames, time range and what happens outside it.
  std::string describe() const;

private:
  struct Slot {
    long long frame = -1;
    std::vector<std::vector<double>> u; // per axis, owned cells
  };
  void read_frame(size_t f, Slot& slot) const;
  const Slot& frame(size_t f, size_t keep);
  std::string check_finite(size_t f, const Slot& slot) const;

  const Grid& grid_;
  std::string text_;
  std::vector<std::string> datasets_;           // as given
  std::vector<std::vector<std::string>> paths_; // resolved dataset paths per frame
  std::vector<VelocityFrame> frames_;
  std::array<Slot, 2> slots_;
  std::array<double, 3> umax_{0, 0, 0};
};

} // namespace morphogen
