#include "app/png_output.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"
#include "io/slice_gather.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen {

PngOutput::PngOutput(Options& opt, const Simulation& sim) {
  const std::string cmap = opt.choice(
      "png_colormap", "viridis", io::colormap_names(),
      "colour map of the PNG images (coolwarm: diverging, light grey at the middle of the range)");
  style_.colormap = *io::colormap_from_name(cmap);
  style_.scale = static_cast<int>(
      opt.integer("png_scale", 1, 1, 64, "PNG upscale factor: each cell becomes N x N pixels"));
  style_.colorbar =
      opt.flag("png_colorbar", false, "add a colour bar with the lo, middle and hi values");
  style_.bits = std::stoi(opt.choice("png_bits", "8", {"8", "16"},
                                     "PNG bit depth: 8 (colour map) or 16 (16-bit grey texture)"));
  fixed_ = opt.choice("png_range", "fixed", {"fixed", "each"},
                      "colour range of a species' images: fixed (the first image's min/max, "
                      "widened when a later image exceeds it) or each (every image its own "
                      "min/max); -png_range_S overrides") == "fixed";
  if (style_.bits == 16 && style_.colorbar)
    throw UserError("-png_colorbar true: not available with -png_bits 16 (16-bit images are grey "
                    "textures without a colour bar); allowed with -png_bits 8");
  if (style_.bits == 16 && opt.is_set("png_colormap") && style_.colormap != io::Colormap::grey)
    throw UserError("-png_colormap " + cmap + ": -png_bits 16 writes grey images; allowed grey " +
                    "(or -png_bits 8)");
  seen_.assign(sim.species().size(), {1.0, 0.0});
}

std::array<double, 2> PngOutput::range(const Simulation& sim, int s, double lo, double hi) {
  const auto& fixed = sim.output().png_range[s];
  if (fixed[0] < fixed[1]) return fixed;
  if (!fixed_ || !std::isfinite(lo) || !std::isfinite(hi)) return {lo, hi};
  auto& r = seen_[s];
  if (r[0] > r[1]) r = {lo, hi}; // the first image
  r = {std::min(r[0], lo), std::max(r[1], hi)};
  return r;
}

void PngOutput::write(Simulation& sim, const std::string& tag) {
  const Grid& g = sim.grid();
  const PetscInt k = g.dim() == 3 ? g.spec().n[2] / 2 : 0;
  int rank = 0;
  MPI_Comm_rank(g.comm(), &rank);
  std::string err;
  LogScope log_scope(log_events().output);
  for (int s : sim.output().png_species) {
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(sim.state()[s], &a));
    std::vector<double> slice = io::gather_xy_slice(g, a, k);
    MG_PETSC(VecRestoreArrayRead(sim.state()[s], &a));
    if (rank != 0 || !err.empty()) continue;
    double lo = *std::min_element(slice.begin(), slice.end());
    double hi = *std::max_element(slice.begin(), slice.end());
    const auto r = range(sim, s, lo, hi);
    const std::string path = sim.output().dir + "/" + sim.species()[s] + "_" + tag + ".png";
    try {
      io::write_field_png(path, static_cast<int>(g.spec().n[0]), static_cast<int>(g.spec().n[1]),
                          slice.data(), r[0], r[1], style_);
    } catch (const UserError& e) {
      err = std::string("-output_dir ") + sim.output().dir + ": " + e.what();
    }
  }
  throw_if_any(g.comm(), err);
}

} // namespace morphogen
