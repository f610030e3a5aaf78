#include "bench/bench_fused.hpp"

#include "app/simulation.hpp"
#include "bench/bench_kernel_rate.hpp"
#include "bench/bench_scoped_options.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

namespace morphogen {

namespace {

// Best seconds per step over `reps` blocks of `steps` steps taken in passes of k.
double seconds_per_step(MPI_Comm comm, Simulation& sim, PetscInt k, PetscInt steps, int reps) {
  sim.advance(k); // warm-up (builds the fused sweep's buffers)
  double best = 1e30;
  for (int rep = 0; rep < reps; ++rep) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    for (PetscInt n = 0; n < steps; n += k)
      sim.advance(k);
    MPI_Barrier(comm);
    best = std::min(best, (MPI_Wtime() - t0) / static_cast<double>(steps));
  }
  return best;
}

void set_options(const std::vector<std::pair<std::string, std::string>>& o, bool clear) {
  for (const auto& [k, v] : o)
    if (clear)
      MG_PETSC(PetscOptionsClearValue(nullptr, k.c_str()));
    else
      MG_PETSC(PetscOptionsSetValue(nullptr, k.c_str(), v.c_str()));
}

} // namespace

FusedSettings read_fused_settings(Options& opt) {
  FusedSettings fs;
  const auto ks =
      opt.list("bench_fuse_steps", {"4", "8"}, 0, 8,
               "fused explicit steps per pass timed against 1, each in [0, 64] (0: only the "
               "one-step baseline; empty: skip the section)");
  fs.ns = opt.list("bench_fuse_n", {"2048", "4096"}, 1, 4, "grid sides of the fused-steps cases");
  fs.stencil =
      opt.choice("bench_fuse_stencil", "9pt", {"5pt", "9pt"}, "stencil of the fused-steps cases");
  fs.steps = opt.integer("bench_fuse_steps_timed", 48, 8, 100000,
                         "timed steps per fused-steps case (rounded to a multiple of k)");
  // Each k and n checked here, with the option it came from (not later as -explicit_fuse_steps
  // or -grid_n, and no value skipped silently).
  for (const auto& k : ks) {
    fs.depth.push_back(Options::parse_int("bench_fuse_steps", k));
    if (fs.depth.back() < 0 || fs.depth.back() > 64)
      throw UserError("-bench_fuse_steps " + k + ": out of range, allowed [0, 64]");
  }
  for (const auto& n : fs.ns) {
    const PetscInt side = Options::parse_int("bench_fuse_n", n);
    if (side < 8 || side > 65536)
      throw UserError("-bench_fuse_n " + n + ": out of range, allowed [8, 65536]");
  }
  return fs;
}

void bench_fused(MPI_Comm comm, Options& opt, const FusedSettings& fs, double roof,
                 const MachineInfo& machine) {
  if (fs.depth.empty()) return;
  const auto& depth = fs.depth;
  const auto& stencil = fs.stencil;
  const PetscInt steps = fs.steps;
  const PetscInt kmax = *std::max_element(depth.begin(), depth.end());
  print_row_kernel_bounds(comm, stencil, 2, roof, 512); // 2 x 3 rows of 4 KiB: in L1
  if (kmax > 1) // rows of a 4096-wide slab's tiles at k = 8 (FusedSweep's automatic width)
    print_fused_ring_bound(comm, stencil, roof, 2048, static_cast<int>(kmax));
  for (const auto& n : fs.ns) {
    const std::vector<std::pair<std::string, std::string>> o = {
        {"-model", "gray_scott"},
        {"-grid_n", n + "," + n},
        {"-grid_L", "2.5"},
        {"-grid_bc", "periodic"},
        {"-stencil", stencil},
        {"-explicit_fuse_steps", std::to_string(std::max<PetscInt>(kmax, 1))},
        {"-init_a", "0.25*square(1.25,1.25,0.1) +- 1%"},
        {"-init_b", "1 - 0.5*square(1.25,1.25,0.1)"}};
    apply_integrator_options(); // before the section's own -explicit_fuse_steps
    set_options(o, false);
    double base = 0;
    {
      Simulation sim(comm, opt, "");
      const double cells = static_cast<double>(sim.grid().global_cells());
      base = cells / seconds_per_step(comm, sim, 1, steps, 3);
      // Issue 13 part 2: one step per pass, out of cache (2048^2, 4096^2): >= 0.95.
      PetscPrintf(comm,
                  "explicit_fused grid=%sx%s stencil=%s k=1 cell_updates_per_s=%.4e "
                  "roofline_fraction=%.3f target>=0.95 %s%s\n",
                  n.c_str(), n.c_str(), stencil.c_str(), base, base / roof,
                  base / roof >= 0.95 ? "met" : "NOT met", l3_note(cells, machine).c_str());
      for (PetscInt k : depth) {
        if (k < 1 || k > sim.fuse_steps()) continue;
        const PetscInt timed = (steps + k - 1) / k * k;
        const double cups = cells / seconds_per_step(comm, sim, k, timed, 3);
        PetscPrintf(comm,
                    "explicit_fused grid=%sx%s stencil=%s k=%lld cell_updates_per_s=%.4e "
                    "vs_k1=%.2f roofline_fraction=%.3f target>=1.5 %s\n",
                    n.c_str(), n.c_str(), stencil.c_str(), static_cast<long long>(k), cups,
                    cups / base, cups / roof, cups / roof >= 1.5 ? "met" : "NOT met");
      }
    }
    set_options(o, true);
  }
}

} // namespace morphogen
