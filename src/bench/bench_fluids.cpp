#include "bench/bench_fluids.hpp"

#include "app/simulation.hpp"
#include "bench/bench_scoped_options.hpp"
#include "bench/bench_timing.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace morphogen {

namespace {

const char* const kKeys[] = {
    "-model", "-grid_n", "-grid_L", "-grid_bc",         "-integrator",      "-advect", "-fluid",
    "-dt",    "-init_a", "-init_b", "-fluid_viscosity", "-fluid_lid_speed", "-summary"};

// Seconds per step of a cavity Gray-Scott run at n^2: the whole step (fluid when `fluid`,
// advection when `advect`, split RD always), best of 2 repetitions of `steps` steps.
double seconds_per_step(MPI_Comm comm, Options& opt, int n, int steps, bool fluid, bool advect) {
  for (const char* k : kKeys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  const std::string grid = std::to_string(n) + "," + std::to_string(n);
  std::vector<std::pair<const char*, std::string>> o = {
      {"-model", "gray_scott"},   {"-grid_n", grid},        {"-grid_L", "2.5"},
      {"-grid_bc", "neumann"},    {"-integrator", "split"}, {"-dt", "5"},
      {"-init_a", "0.25 +- 50%"}, {"-init_b", "0.5 +- 5%"}, {"-summary", "false"}};
  if (fluid) {
    o.push_back({"-fluid", "cavity"});
    o.push_back({"-fluid_viscosity", "1e-5"});
    o.push_back({"-fluid_lid_speed", "0.002"});
  }
  if (advect) o.push_back({"-advect", "a,b"});
  for (auto& [k, v] : o)
    MG_PETSC(PetscOptionsSetValue(nullptr, k, v.c_str()));
  apply_integrator_options();
  Simulation sim(comm, opt, "");
  sim.step(); // warm up (matrices, preconditioners)
  return best_seconds_per_step(comm, sim, steps, 2);
}

} // namespace

void bench_fluids(MPI_Comm comm, Options& opt, int max_n, int steps) {
  const double paper[4] = {223, 78.5, 21.5, 5.5};
  PetscPrintf(comm, "fluids: lid-driven cavity + Gray-Scott, split integrator (implicit RD), "
                    "a,b advected; paper = stable-ARD Table 1 (Cell, fluids + RD)\n");
  for (int q = 0, n = 128; n <= max_n && q < 4; n *= 2, ++q) {
    const double rd = seconds_per_step(comm, opt, n, steps, false, false);
    const double fl = seconds_per_step(comm, opt, n, steps, true, false);
    const double all = seconds_per_step(comm, opt, n, steps, true, true);
    const double fluid = std::max(fl - rd, 1e-9), adv = std::max(all - fl, 0.0);
    PetscPrintf(comm,
                "fluids_%d fps_fluids_only=%.2f fps_fluids_ard=%.2f paper_fps=%.1f "
                "ms_fluid=%.2f ms_advection=%.2f ms_rd=%.2f\n",
                n, 1.0 / fluid, 1.0 / all, paper[q], 1e3 * fluid, 1e3 * adv, 1e3 * rd);
  }
  for (const char* k : kKeys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
}

} // namespace morphogen
