#include "operators/advection_setup.hpp"

#include "core/user_error.hpp"

#include <algorithm>

namespace morphogen {

namespace {

const char* kOptions[] = {"advection_scheme", "advection_backtrace",
                          "advection_halo",   "velocity_x",
                          "velocity_y",       "velocity_z",
                          "velocity_file",    "velocity_datasets",
                          "velocity_times",   "velocity_time_attribute"};
const char* kExpressions[] = {"velocity_x", "velocity_y", "velocity_z"};
const char* kFileOptions[] = {"velocity_datasets", "velocity_times", "velocity_time_attribute"};

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v)
    s += (s.empty() ? "" : ", ") + x;
  return s;
}

// -advect: species names, each once.
void read_species(Options& opt, const std::string& text, const std::vector<std::string>& species,
                  AdvectionSettings& set) {
  const auto names = opt.list("advect", {}, 1, species.size(),
                              "species carried by the velocity -velocity_x, -velocity_y, "
                              "... (semi-Lagrangian, after reaction and diffusion each step)");
  for (const auto& n : names) {
    const auto it = std::find(species.begin(), species.end(), n);
    if (it == species.end())
      throw UserError("-advect " + text + ": no species '" + n + "', allowed " + joined(species));
    const int s = static_cast<int>(it - species.begin());
    if (std::find(set.species.begin(), set.species.end(), s) != set.species.end())
      throw UserError("-advect " + text + ": species '" + n + "' given twice");
    set.species.push_back(s);
    set.names.push_back(n);
  }
}

// -velocity_file, or null. Refused beside -fluid or -velocity_x/_y/_z; its companions
// (-velocity_datasets, ...) are refused without it.
std::unique_ptr<VelocityFile> read_velocity_file(Options& opt, const Grid& grid,
                                                 const std::string& base_dir,
                                                 const VelocitySource* fluid) {
  const auto file = opt.get("velocity_file",
                            "advection velocity from HDF5 files: one file (steady), a comma list "
                            "or a .series JSON file (linear in t between frames)");
  if (!file) {
    for (const char* k : kFileOptions)
      if (opt.is_set(k))
        throw UserError(std::string("-") + k + ": applies with -velocity_file only");
    return nullptr;
  }
  if (fluid)
    throw UserError("-velocity_file " + *file + ": the velocity comes from " +
                    fluid->option_text() + "; drop -velocity_file or the fluid");
  for (const char* k : kExpressions)
    if (opt.is_set(k))
      throw UserError(std::string("-") + k + ": the velocity comes from -velocity_file " + *file +
                      "; drop -" + k + " or -velocity_file");
  return std::make_unique<VelocityFile>(grid, opt, *file, base_dir);
}

} // namespace

std::unique_ptr<AdvectionStage> read_advection(Options& opt, const Grid& grid,
                                               const std::vector<std::string>& species,
                                               std::uint64_t seed, const std::string& base_dir,
                                               double dt, const VelocitySource* fluid) {
  const auto text = opt.get("advect", "species carried by the velocity (comma-separated)");
  if (!text) {
    for (const char* k : kOptions)
      if (opt.is_set(k))
        throw UserError(std::string("-") + k +
                        ": applies to advected species only; add -advect SPECIES (e.g. -advect " +
                        species[0] + ")");
    return nullptr;
  }
  AdvectionSettings set;
  read_species(opt, *text, species, set);
  set.interp = opt.choice("advection_scheme", "linear", {"linear", "cubic"},
                          "interpolation at the back-traced point: linear (bi/trilinear, "
                          "monotone) or cubic (4-point Lagrange, may overshoot)") == "cubic"
                   ? advect::Interp::Cubic
                   : advect::Interp::Linear;
  set.backtrace = opt.choice("advection_backtrace", "rk2", {"rk2", "euler"},
                             "departure point: rk2 (midpoint rule) or euler (one step back, "
                             "the stable-ARD paper's eq. 20)") == "euler"
                      ? advect::Backtrace::Euler
                      : advect::Backtrace::Rk2;
  set.halo = static_cast<int>(
      opt.integer("advection_halo", 0, 0, AdvectionSettings::kMaxHalo,
                  "halo of the advected species in cells (0: from the largest Courant number "
                  "max|u| dt/h at the start, plus the interpolation stencil)"));
  if (auto file = read_velocity_file(opt, grid, base_dir, fluid))
    return std::make_unique<AdvectionStage>(grid, std::move(file), std::move(set), dt);
  if (fluid) {
    for (const char* k : {"velocity_x", "velocity_y", "velocity_z"})
      if (opt.is_set(k))
        throw UserError(std::string("-") + k + ": the velocity comes from " + fluid->option_text() +
                        "; drop -" + k + " or the fluid");
    return std::make_unique<AdvectionStage>(grid, *fluid, std::move(set), dt);
  }
  auto velocity = std::make_unique<VelocityField>(grid, opt, seed, base_dir);
  return std::make_unique<AdvectionStage>(grid, std::move(velocity), std::move(set), dt);
}

} // namespace morphogen
