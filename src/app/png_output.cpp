#include "app/png_output.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"
#include "io/slice_image.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace morphogen {

PngOutput::PngOutput(Options& opt, const Simulation& sim) {
  const std::string cmap = opt.choice(
      "png_colormap", "viridis", io::colormap_names(),
      "colour map of the PNG images (coolwarm: diverging, light grey at the middle of the range)");
  style_.colormap = *io::colormap_from_name(cmap);
  style_.scale = static_cast<int>(
      opt.integer("png_scale", 1, 1, 64, "PNG upscale factor: each cell becomes N x N pixels"));
  max_size_ = opt.integer("png_max_size", 1024, 0, 1 << 24,
                          "PNG images of slices larger than N cells along x or y show block means "
                          "of f x f cells, f = ceil(max(nx,ny)/N); 0: full resolution");
  if (max_size_ > 0 && max_size_ < 16)
    throw UserError("-png_max_size " + std::to_string(max_size_) +
                    ": allowed 0 (full resolution) or an image size of at least 16 pixels");
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

namespace {

// Copies each file of `from` to the same name with `old_tag` replaced by `tag` (rank 0); an
// error message or "".
std::string copy_images(const std::vector<std::string>& from, const std::string& old_tag,
                        const std::string& tag) {
  for (const std::string& src : from) {
    const size_t at = src.rfind("_" + old_tag + ".png");
    const std::string dst = src.substr(0, at) + "_" + tag + ".png";
    std::error_code ec;
    std::filesystem::copy_file(src, dst + ".tmp", std::filesystem::copy_options::overwrite_existing,
                               ec);
    if (!ec) std::filesystem::rename(dst + ".tmp", dst, ec);
    if (ec) {
      std::filesystem::remove(dst + ".tmp", ec);
      return "cannot write PNG file '" + dst + "': " + ec.message();
    }
  }
  return "";
}

} // namespace

void PngOutput::write(Simulation& sim, const std::string& tag) {
  const double t0 = MPI_Wtime();
  const Grid& g = sim.grid();
  int rank = 0;
  MPI_Comm_rank(g.comm(), &rank);
  std::string err;
  LogScope log_scope(log_events().output);
  const long long step = static_cast<long long>(sim.step_index()) * 16 + sim.level();
  if (step == last_step_ && !last_tag_.empty()) {
    if (rank == 0) err = copy_images(last_paths_, last_tag_, tag);
  } else {
    err = draw(sim, tag);
  }
  throw_if_any(g.comm(), err);
  last_step_ = step;
  last_tag_ = tag;
  seconds_ += MPI_Wtime() - t0;
  files_ += static_cast<int>(sim.output().png_species.size());
}

std::string PngOutput::draw(Simulation& sim, const std::string& tag) {
  const Grid& g = sim.grid();
  const PetscInt k = g.dim() == 3 ? g.spec().n[2] / 2 : 0;
  int rank = 0;
  MPI_Comm_rank(g.comm(), &rank);
  std::string err;
  last_paths_.clear();
  for (int s : sim.output().png_species) {
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(sim.state()[s], &a));
    const io::SliceImage img = io::gather_xy_slice_image(g, a, k, max_size_);
    MG_PETSC(VecRestoreArrayRead(sim.state()[s], &a));
    if (rank != 0 || !err.empty()) continue;
    const auto r = range(sim, s, img.lo, img.hi);
    const std::string path = sim.output().dir + "/" + sim.species()[s] + "_" + tag + ".png";
    try {
      io::write_field_png(path, img.width, img.height, img.value.data(), r[0], r[1], style_);
      last_paths_.push_back(path);
    } catch (const UserError& e) {
      err = std::string("-output_dir ") + sim.output().dir + ": " + e.what();
    }
  }
  return err;
}

} // namespace morphogen
