#include "operators/fluid_setup.hpp"

#include "core/collective_error.hpp"
#include "core/user_error.hpp"
#include "fields/value_spec.hpp"

#include <algorithm>
#include <limits>

namespace morphogen {

namespace {

const char* kOptions[] = {"fluid_viscosity", "fluid_lid_speed", "fluid_inflow",
                          "fluid_obstacle",  "fluid_substeps",  "fluid_scheme"};

// The obstacle expression at the owned cells (x fastest).
std::vector<double> obstacle(Options& opt, const Grid& grid, std::uint64_t seed,
                             const std::string& base_dir) {
  const std::string text =
      opt.string("fluid_obstacle", "0",
                 "solid obstacle of the fluid: cells where this expression of x, y is > 0.5 (e.g. "
                 "\"(x-0.3*Lx)^2+(y-0.5*Ly)^2 < (0.1*Lx)^2\"); zero velocity, no-slip");
  ValueSpec spec("fluid_obstacle", text, grid.spec(), seed, base_dir);
  if (spec.uses_time())
    throw UserError("-fluid_obstacle " + text +
                    ": the obstacle cannot depend on t (it is evaluated once, at the start)");
  std::vector<double> m(static_cast<size_t>(grid.owned().size()));
  std::string err;
  try {
    const Box& ob = grid.owned();
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        m[static_cast<size_t>(grid.owned_index(i, j, 0))] = spec.at_cell(i, j, 0);
  } catch (const UserError& e) {
    err = e.what();
  }
  throw_if_any(grid.comm(), err);
  long long fluid_cells = std::count_if(m.begin(), m.end(), [](double v) { return !(v > 0.5); });
  MPI_Allreduce(MPI_IN_PLACE, &fluid_cells, 1, MPI_LONG_LONG, MPI_SUM, grid.comm());
  if (fluid_cells == 0)
    throw UserError("-fluid_obstacle " + text +
                    ": the obstacle (cells where it is > 0.5) covers every cell; allowed: an "
                    "obstacle that leaves fluid cells");
  return m;
}

void register_ksp_options(Options& opt) {
  for (const char* p : {"fluid_", "fluid_visc_"})
    for (const char* k :
         {"ksp_type", "pc_type", "ksp_rtol", "ksp_atol", "ksp_max_it", "ksp_monitor", "ksp_view",
          "ksp_converged_reason", "pc_mg_levels", "pc_mg_galerkin", "pc_gamg_threshold",
          "pc_hypre_type", "ksp_norm_type", "mg_levels_ksp_type", "mg_levels_pc_type"})
      opt.known(std::string(p) + k);
}

// A cavity's or channel's walls bound the grid: a periodic axis would let the species wrap
// through a wall (or from the channel's outflow back to its inflow).
void check_walls(const Grid& grid, const std::string& option_text) {
  const auto& bc = grid.spec().bc;
  if (bc[0] != Boundary::Periodic && bc[1] != Boundary::Periodic) return;
  throw UserError(option_text + " with -grid_bc " + boundary_name(bc[0]) + "," +
                  boundary_name(bc[1]) +
                  ": the flow has walls (or inflow and outflow) on x and y, so neither axis may be "
                  "periodic; allowed: "
                  "-grid_bc neumann or dirichlet on both axes (or -fluid periodic)");
}

} // namespace

std::unique_ptr<FluidSolver> read_fluid(Options& opt, const Grid& grid, std::uint64_t seed,
                                        const std::string& base_dir) {
  const std::string kind =
      opt.choice("fluid", "none", {"none", "cavity", "channel", "periodic"},
                 "stable-fluids velocity for -advect (2-D): cavity (lid-driven, no-slip walls), "
                 "channel (inflow left, outflow right, free-slip bottom/top), periodic");
  if (kind == "none") {
    for (const char* k : kOptions)
      if (opt.is_set(k))
        throw UserError(std::string("-") + k +
                        ": applies to the fluid solver only; add -fluid cavity|channel|periodic");
    return nullptr;
  }
  FluidSettings s;
  s.kind = kind == "cavity" ? fluid::Kind::Cavity
                            : (kind == "channel" ? fluid::Kind::Channel : fluid::Kind::Periodic);
  s.option_text = "-fluid " + kind;
  if (grid.dim() != 2)
    throw UserError(s.option_text + ": the fluid solver is 2-D only (the grid is " +
                    std::to_string(grid.dim()) + "-D; use a 2-D -grid_n nx,ny)");
  if (s.kind != fluid::Kind::Periodic) check_walls(grid, s.option_text);
  s.viscosity = opt.real("fluid_viscosity", 0.01, 0.0, std::numeric_limits<double>::max(),
                         "kinematic viscosity nu of the fluid (implicit; 0: inviscid)");
  if (s.kind == fluid::Kind::Cavity)
    s.lid = opt.real("fluid_lid_speed", 1.0, -1e6, 1e6,
                     "cavity: speed of the top wall (along +x); Re = U Lx / nu");
  if (s.kind == fluid::Kind::Channel)
    s.inflow =
        opt.real("fluid_inflow", 1.0, -1e6, 1e6, "channel: inflow speed (+x) on the left face");
  for (const char* k : {"fluid_lid_speed", "fluid_inflow"})
    if (opt.is_set(k) && ((s.kind == fluid::Kind::Cavity) != (std::string(k) == "fluid_lid_speed")))
      throw UserError(std::string("-") + k + ": does not apply to -fluid " + kind + " (" +
                      (std::string(k) == "fluid_lid_speed" ? "cavity" : "channel") + " only)");
  s.substeps = static_cast<int>(
      opt.integer("fluid_substeps", 1, 1, 1000, "fluid substeps of dt/N per run step"));
  s.interp = opt.choice("fluid_scheme", "linear", {"linear", "cubic"},
                        "interpolation of the fluid's velocity self-advection: linear "
                        "(Stam's, diffusive) or cubic (sharper, may overshoot)") == "cubic"
                 ? advect::Interp::Cubic
                 : advect::Interp::Linear;
  register_ksp_options(opt);
  return std::make_unique<FluidSolver>(grid, s, obstacle(opt, grid, seed, base_dir));
}

} // namespace morphogen
