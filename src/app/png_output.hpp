// PNG quick-looks of a run: the image options and the colour range kept across a run.
//
// Options (read by the constructor, so -help lists them and bad values fail before any output):
//   -png_colormap grey|viridis|magma|coolwarm  colour map (coolwarm: diverging)
//   -png_scale N       each cell becomes N x N pixels (nearest neighbour), 1..64
//   -png_colorbar      a colour bar with the lo, middle and hi values right of the field
//   -png_bits 8|16     16: 16-bit greyscale (textures; no colour map or bar)
//   -png_range fixed|each
//       fixed (default): the images of a species share one range within a run: the min/max of
//       its first image, widened (never narrowed) when a later image exceeds it;
//       each: every image is stretched to its own min/max.
//   -png_range_S LO,HI (read by Simulation) overrides both for species S.
// Images are written by rank 0 from a gathered x-y slice (the middle z slice in 3-D).
#pragma once

#include "app/simulation.hpp"
#include "core/options.hpp"
#include "io/png_file.hpp"

#include <array>
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

private:
  // The colour range of species s for an image whose own min/max is [lo, hi] (rank 0).
  std::array<double, 2> range(const Simulation& sim, int s, double lo, double hi);

  io::FieldImageStyle style_;
  bool fixed_ = true;
  std::vector<std::array<double, 2>> seen_; // per species: the run's range so far (lo > hi: none)
};

} // namespace morphogen
