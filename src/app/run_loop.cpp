#include "app/run_loop.hpp"

#include "app/reaction_stiffness.hpp"
#include "core/collective_error.hpp"
#include "core/log_events.hpp"
#include "core/user_error.hpp"
#include "integrators/kernel_choice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace morphogen {

bool run_loop(Simulation& sim, PetscInt end_step, RunOutput& output, PngOutput& pngs,
              bool final_level) {
  MPI_Comm comm = sim.grid().comm();
  const PetscInt first = sim.step_index();
  const PetscInt steps = end_step - first;
  const auto& out = sim.output();
  const double cells = static_cast<double>(sim.grid().global_cells());
  char tag[32];
  const double t0 = MPI_Wtime();
  double t_last = t0;
  PetscInt step_last = 0;
  auto check_finite = [&] { output.check_finite(sim); };
  // Images are this run's output too: the first one commits the directory (RunOutput::commit);
  // a failed write stops every rank with exit code 4.
  auto write_images = [&](const std::string& image_tag) {
    output.commit();
    try {
      pngs.write(sim, image_tag);
    } catch (const UserError& e) {
      output.images_failed(e.what());
    }
  };
  if (sim.level() == 0) warn_if_reaction_stiff(sim);
  if (sim.fluid()) PetscPrintf(comm, "%s\n", sim.fluid()->describe().c_str());
  if (sim.advection()) PetscPrintf(comm, "%s\n", sim.advection()->describe().c_str());
  // Steps in the pass starting at loop step n: up to sim.fuse_steps(), ending before any step
  // that checks, writes, samples or reports something (those end a pass).
  auto pass_length = [&](PetscInt n) {
    const PetscInt kmax = std::min(sim.fuse_steps(), steps - n + 1);
    double t = sim.time();
    PetscInt b = 1;
    for (; b < kmax; ++b) {
      const PetscInt m = n + b - 1, index = first + m;
      t += sim.dt(); // the clock after step m, as Simulation advances it
      const bool png = out.png_every > 0 && index % out.png_every == 0;
      if (m % out.nan_check_every == 0 || m % out.progress_every == 0 || png ||
          !output.quiet_at(sim, index, t))
        break;
    }
    return b;
  };
  PetscInt passes = 0;
  for (PetscInt n = 1; n <= steps; ++n) {
    const PetscInt pass = pass_length(n);
    sim.advance(pass);
    ++passes;
    if (pass > 1) {
      output.count_fused_steps(sim, pass - 1);
      n += pass - 1;
    }
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
      write_images(tag);
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
  if (sim.fuse_steps() > 1)
    PetscPrintf(comm, "fused steps: %lld steps in %lld passes (up to %lld steps each)\n",
                static_cast<long long>(steps), static_cast<long long>(passes),
                static_cast<long long>(std::min(sim.fuse_steps(), steps)));
  if (const SplitIntegrator* split = sim.split_integrator())
    PetscPrintf(comm, "split: %ld reaction substeps inside the diffusion's pass\n",
                split->planes_fused_substeps());
  const std::string width = sim.explicit_vector_width();
  if (!width.empty() && wide_vectors_available())
    PetscPrintf(comm, "explicit kernel (rank 0): %s\n", width.c_str());
  if (final_level) {
    check_finite();
    std::snprintf(tag, sizeof tag, "%07lld", static_cast<long long>(sim.step_index()));
    write_images(tag);
    write_images("final");
    output.note_images(pngs.seconds(), pngs.files());
    output.finish(sim);
  }
  return false;
}

} // namespace morphogen
