#include "app/run_loop.hpp"

#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"
#include "io/png_file.hpp"
#include "io/slice_gather.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace morphogen {

void write_pngs(Simulation& sim, const std::string& tag) {
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
    double lo = sim.output().png_range[s][0], hi = sim.output().png_range[s][1];
    if (!(lo < hi)) {
      lo = *std::min_element(slice.begin(), slice.end());
      hi = *std::max_element(slice.begin(), slice.end());
    }
    const std::string path = sim.output().dir + "/" + sim.species()[s] + "_" + tag + ".png";
    try {
      io::write_field_png(path, static_cast<int>(g.spec().n[0]), static_cast<int>(g.spec().n[1]),
                          slice.data(), lo, hi);
    } catch (const UserError& e) {
      err = std::string("-output_dir ") + sim.output().dir + ": " + e.what();
    }
  }
  throw_if_any(g.comm(), err);
}

bool run_loop(Simulation& sim, PetscInt end_step, RunOutput& output, bool final_level) {
  MPI_Comm comm = sim.grid().comm();
  const PetscInt first = sim.step_index();
  const PetscInt steps = end_step - first;
  const auto& out = sim.output();
  const double cells = static_cast<double>(sim.grid().global_cells());
  char tag[32];
  const double t0 = MPI_Wtime();
  double t_last = t0;
  PetscInt step_last = 0;
  auto check_finite = [&] {
    try {
      sim.check_finite();
    } catch (const UserError& e) {
      throw UserError(std::string(e.what()) + "; last good checkpoint: " +
                      (output.last_checkpoint().empty() ? "none written by this run"
                                                        : output.last_checkpoint()));
    }
  };
  for (PetscInt n = 1; n <= steps; ++n) {
    sim.step();
    if (n % out.nan_check_every == 0 || n == steps) check_finite();
    if (output.after_step(sim)) {
      PetscPrintf(comm,
                  "stopped by %s at step %lld (t %.6g): checkpoint %s written; continue with "
                  "-restart latest (exit code %d)\n",
                  output.stop_reason().c_str(), static_cast<long long>(sim.step_index()),
                  sim.time(), output.last_checkpoint().c_str(), kExitResubmit);
      return true;
    }
    if (out.png_every > 0 && sim.step_index() % out.png_every == 0 && n != steps) {
      std::snprintf(tag, sizeof tag, "%07lld", static_cast<long long>(sim.step_index()));
      write_pngs(sim, tag);
    }
    if (n % out.progress_every == 0 || n == steps) {
      const double now = MPI_Wtime();
      const double rate =
          (now - t_last) > 0 ? cells * static_cast<double>(n - step_last) / (now - t_last) : 0;
      const double elapsed = now - t0;
      const double eta = elapsed / static_cast<double>(n) * static_cast<double>(steps - n);
      MG_PETSC(PetscPrintf(
          comm,
          "step %lld/%lld  t %.6g  %5.1f%%  %.3e cell-updates/s  elapsed %.1f s  "
          "ETA %.1f s\n",
          static_cast<long long>(sim.step_index()), static_cast<long long>(end_step), sim.time(),
          100.0 * static_cast<double>(n) / static_cast<double>(steps), rate, elapsed, eta));
      t_last = now;
      step_last = n;
    }
  }
  if (final_level) {
    check_finite();
    std::snprintf(tag, sizeof tag, "%07lld", static_cast<long long>(sim.step_index()));
    write_pngs(sim, tag);
    write_pngs(sim, "final");
    output.finish(sim);
  }
  return false;
}

} // namespace morphogen
