// PNG quick-looks of a run: the image options and the colour range kept across a run.
//
// Options (read by the constructor, so -help lists them and bad values fail before any output):
//   -png_colormap grey|viridis|magma|coolwarm  colour map (coolwarm: diverging)
//   -png_max_size N    a slice larger than N cells along x or y is shown as block means of
//                      f x f cells, f = ceil(max(nx, ny) / N) (io/block_mean_kernel.hpp: the
//                      same image on any rank count); 0: always full resolution. Default 1024.
//   -png_scale N       each pixel (cell or block) becomes N x N pixels (nearest neighbour), 1..64
//   -png_colorbar      a colour bar with the lo, middle and hi values right of the field
//   -png_bits 8|16     16: 16-bit greyscale (textures; no colour map or bar)
//   -png_range fixed|each
//       fixed (default): the images of a species share one range within a run: the min/max of
//       its first image, widened (never narrowed) when a later image exceeds it;
//       each: every image is stretched to its own min/max.
//   -png_range_S LO,HI (read by Simulation) overrides both for species S.
// Images are written by rank 0 from a gathered x-y slice (the middle z slice in 3-D); only the
// reduced image travels when the slice is reduced. Writing the same step again under another
// tag (the final images) copies the files just written instead of drawing them again.
#pragma once

#include "app/simulation.hpp"
#include "core/options.hpp"
#include "io/png_file.hpp"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace morphogen {

class PngOutput {
public:
  // Reads and validates the -png_* options above; sim gives the species.
  PngOutput(Options& opt, const Simulation& sim);

  // Collective: writes <species>_<tag>.png of every -png_species into -output_dir.
  void write(Simulation& sim, const std::string& tag);

  const io::FieldImageStyle& style() const { return style_; }
  long long max_size() const { return max_size_; }
  // Seconds spent in write() and the number of image files written, for the run's log.
  double seconds() const { return seconds_; }
  int files() const { return files_; }

private:
  // Gathers and writes the images of this step (rank 0 writes); an error message or "".
  std::string draw(Simulation& sim, const std::string& tag);
  // The colour range of species s for an image whose own min/max is [lo, hi] (rank 0).
  std::array<double, 2> range(const Simulation& sim, int s, double lo, double hi);

  io::FieldImageStyle style_;
  bool fixed_ = true;
  std::vector<std::array<double, 2>> seen_; // per species: the run's range so far (lo > hi: none)
  long long max_size_ = 1024;
  double seconds_ = 0;
  int files_ = 0;
  long long last_step_ = -1; // step (x16 + level) of the images last written
  std::string last_tag_;
  std::vector<std::string> last_paths_; // their files (rank 0)
};

} // namespace morphogen
