#include "operators/advection_setup.hpp"

#include "core/user_error.hpp"

#include <algorithm>

namespace morphogen {

namespace {

const char* kOptions[] = {"advection_scheme", "advection_backtrace", "advection_halo",
                          "velocity_x",       "velocity_y",          "velocity_z"};

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
