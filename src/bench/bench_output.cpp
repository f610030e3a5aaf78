#include "bench/bench_output.hpp"

#include "app/png_output.hpp"
#include "app/simulation.hpp"
#include "bench/bench_scoped_options.hpp"
#include "fields/field_fill.hpp"

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace morphogen {

namespace {

// Seconds to fill one field of `text` (best of 2), on every rank together.
double fill_seconds(const Grid& grid, const std::string& text) {
  ValueSpec vs("params_alpha", text, grid.spec(), 1);
  VecH v = grid.create_global();
  double best = 1e30;
  for (int rep = 0; rep < 2; ++rep) {
    PetscScalar* a;
    MG_PETSC(VecGetArray(v, &a));
    MPI_Barrier(grid.comm());
    const double t0 = MPI_Wtime();
    fill_field(grid, vs, a, ArrayLayout::Owned, -1e300, 1e300);
    MPI_Barrier(grid.comm());
    best = std::min(best, MPI_Wtime() - t0);
    MG_PETSC(VecRestoreArray(v, &a));
  }
  return best;
}

const char* const kKeys[] = {"-model",    "-grid_n", "-params_alpha", "-params_beta",
                             "-params_s", "-D_a",    "-D_b",          "-init_a",
                             "-init_b",   "-dt",     "-output_dir"};

} // namespace

void bench_output(MPI_Comm comm, Options& opt, int n) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  char buf[64];
  std::snprintf(buf, sizeof buf, "/tmp/morphogen-bench-output-%d", static_cast<int>(getpid()));
  MPI_Bcast(buf, sizeof buf, MPI_CHAR, 0, comm); // rank 0's name on every rank
  const std::string dir = buf;
  if (rank == 0) std::filesystem::create_directories(dir);
  const std::string grid_n = std::to_string(n) + "," + std::to_string(n);
  const std::pair<const char*, std::string> opts[] = {{"-model", "turing"},
                                                      {"-grid_n", grid_n},
                                                      {"-params_alpha", "12 +- 0.1% gauss"},
                                                      {"-params_beta", "16 +- 0.1% gauss"},
                                                      {"-params_s", "1/128"},
                                                      {"-D_a", "0.0625"},
                                                      {"-D_b", "0.25"},
                                                      {"-init_a", "4"},
                                                      {"-init_b", "4"},
                                                      {"-dt", "0.5"},
                                                      {"-output_dir", dir}};
  for (const auto& [k, v] : opts)
    MG_PETSC(PetscOptionsSetValue(nullptr, k, v.c_str()));
  {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    apply_integrator_options();
    Simulation sim(comm, opt, "");
    const double setup = MPI_Wtime() - t0;
    const double cells = static_cast<double>(sim.grid().global_cells());
    // The 2 steps as a run of these settings takes them: one fused pass where the default fuses
    // (its buffers count in the peak), else single steps.
    if (sim.fuse_steps() >= 2)
      sim.advance(2);
    else
      for (int i = 0; i < 2; ++i)
        sim.step();
    PngOutput pngs(opt, sim);
    MPI_Barrier(comm);
    const double t1 = MPI_Wtime();
    pngs.write(sim, "bench");
    MPI_Barrier(comm);
    const double png = MPI_Wtime() - t1;
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    double rss = static_cast<double>(ru.ru_maxrss) * 1024.0, rss_sum = 0;
    MPI_Reduce(&rss, &rss_sum, 1, MPI_DOUBLE, MPI_SUM, 0, comm);
    // The fill timings after the peak is read: their scratch field is the bench's, not the run's.
    const double ns_perturbed = 1e9 * fill_seconds(sim.grid(), "12 +- 0.1% gauss") * size / cells;
    const double ns_expr =
        1e9 * fill_seconds(sim.grid(), "12 + 0.5*sin(x/17)*cos(y/13)") * size / cells;
    auto met = [](bool ok) { return ok ? "met" : "NOT met"; };
    PetscPrintf(comm,
                "output_%dx%d setup_s=%.3f fill_ns_per_cell_perturbed=%.1f "
                "fill_ns_per_cell_expression=%.1f (target <= 50, rank-seconds per cell: %s) "
                "png_s=%.3f (target <= 1, %d species, -png_max_size %lld: %s) "
                "peak_rss_bytes_per_cell=%.1f (target <= 64: setup, 2 steps%s, images, all ranks: "
                "%s)\n",
                n, n, setup, ns_perturbed, ns_expr, met(ns_perturbed <= 50 && ns_expr <= 50), png,
                static_cast<int>(sim.output().png_species.size()), pngs.max_size(), met(png <= 1.0),
                rss_sum / cells, sim.fuse_steps() >= 2 ? " in one fused pass" : "",
                met(rss_sum / cells <= 64));
  }
  for (const char* k : kKeys)
    MG_PETSC(PetscOptionsClearValue(nullptr, k));
  if (rank == 0) {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
}

} // namespace morphogen
