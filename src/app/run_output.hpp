// What a run writes while it steps, and when it stops early:
//  - VTKHDF snapshots (float32/64) every -snapshot_every steps / -snapshot_every_time, and the
//    final state, with the <name>.vtkhdf.series and <name>.xmf indexes; the species plus
//    velocity_x, velocity_y[, _z] when the run advects (-advect) or has a fluid (-fluid);
//  - checkpoints (float64 + /morphogen restart attributes; with -fluid also the fluid's state,
//    FluidSolver::state(), and the attribute fluid = its kind) every -checkpoint_every steps,
//    -checkpoint_every_time, -checkpoint_every_walltime minutes, at the end, and when the run
//    must stop: SIGUSR1/SIGTERM (all ranks agree at the next step) or the -max_walltime budget.
//    Written to <file>.tmp and renamed when complete; the newest -checkpoint_keep are kept.
// A failed write prints one line naming the file and the last good checkpoint and aborts every
// rank with exit code 4 (an HDF5 write that failed on one rank cannot be finished collectively).
#pragma once

#include "app/pattern_summary.hpp"
#include "app/simulation.hpp"
#include "io/series_index.hpp"
#include "io/vtkhdf_file.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen {

constexpr int kExitResubmit = 3; // checkpointed on a signal or the wall-time budget
constexpr int kExitWriteFailed = 4;

class RunOutput {
public:
  // wall_start: MPI_Wtime() when the program started (for -max_walltime).
  RunOutput(MPI_Comm comm, const Options& opt, double wall_start);
  // Removes options_used.yaml.tmp if the run ended before writing anything (see prepare).
  ~RunOutput();
  RunOutput(const RunOutput&) = delete;
  RunOutput& operator=(const RunOutput&) = delete;

  // Before the run: creates -output_dir (failure: UserError, exit 1) and writes the resolved
  // options to options_used.yaml.tmp (failure, e.g. a read-only or full directory: exit 4,
  // nothing touched). The existing output (options_used.yaml, checkpoints) stays as it is
  // until commit().
  void prepare(const Simulation& sim);
  // Before the first file of this run is written (called by every writer, and by run_loop
  // before images): renames options_used.yaml.tmp to options_used.yaml and retires the
  // checkpoints of an earlier run (or, after a restart, those newer than its step), so that
  // input rejected during the run (an expression that fails at a later t) leaves the
  // directory untouched. Rank 0 acts; call on every rank.
  void commit();
  // Collective NaN/Inf/blow-up guard (Simulation::check_finite) whose message names the last
  // good checkpoint (of this run, or the one it restarted from).
  void check_finite(const Simulation& sim) const;
  // Collective: an image (or other output) of this run could not be written: one line naming
  // it and the last good checkpoint, and every rank stops with exit code 4.
  [[noreturn]] void images_failed(const std::string& err) const;

  // Start writing for a (new level's) simulation. restart_step < 0: a fresh run (checkpoints
  // of an earlier run in the directory are retired at commit(), the series starts empty);
  // otherwise the run continues from that step (later checkpoints are retired at commit(),
  // later series entries dropped).
  void begin(Simulation& sim, long long restart_step, PetscInt end_step);
  // After every step. Returns true when the run must stop (a checkpoint has been written).
  bool after_step(Simulation& sim);
  // True when after_step at step n, time t would write nothing and take no sample (steps that
  // may fall inside a fused block; stop signals are polled at the block's end).
  bool quiet_at(const Simulation& sim, PetscInt n, double t) const;
  // A fused block of b steps ended: after_step counts one, this the other b - 1.
  void count_fused_steps(const Simulation& sim, PetscInt extra) {
    cell_updates_ += static_cast<double>(extra) * static_cast<double>(sim.grid().global_cells());
  }
  // Final snapshot and checkpoint of the last level, and summary.json: per species the pattern
  // class and metrics (with the run's dynamics from samples taken every 1/1000 of the run),
  // and the linear stability of the parameters.
  void finish(Simulation& sim);

  // The images' share of the output time (PngOutput::seconds, files), for the log lines that
  // finish() prints: one per writer (snapshots, checkpoints, images, summary) with its time.
  void note_images(double seconds, int files) {
    image_seconds_ = seconds;
    image_files_ = files;
  }

  const std::string& last_checkpoint() const { return last_checkpoint_; }
  const std::string& stop_reason() const { return stop_reason_; }

private:
  void write_snapshot(Simulation& sim);
  void write_checkpoint(Simulation& sim);
  void print_output_times(double summary_seconds) const;
  nlohmann::json classify_all(Simulation& sim) const;
  void collect_on_rank0(MPI_Comm comm, std::vector<nlohmann::json>& c) const;
  [[noreturn]] void write_failed(const std::string& what, const std::string& path,
                                 const std::string& err) const;
  int poll_stop_flags(const Simulation& sim);

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  const Options& opt_;
  std::unique_ptr<io::VtkHdfIO> io_;
  std::unique_ptr<io::SeriesIndex> series_;
  const Grid* grid_ = nullptr;
  double wall_start_ = 0, next_wall_checkpoint_ = 0, last_write_seconds_ = 0;
  double step_seconds_ = 0, last_step_wall_ = 0;
  double loop_seconds_ = 0, cell_updates_ = 0; // time loop totals, for summary.json "run"
  double next_snapshot_time_ = 0, next_checkpoint_time_ = 0;
  long long last_snapshot_step_ = -1, last_checkpoint_step_ = -1;
  std::string last_checkpoint_, stop_reason_;
  std::string dir_;             // -output_dir
  std::string options_tmp_;     // options_used.yaml.tmp until commit() (rank 0)
  bool committed_ = false;      // commit() has run
  bool retire_pending_ = false; // checkpoints to retire at commit()
  long long retire_after_ = -1; // retire those with a step > this (-1: all)
  double snapshot_seconds_ = 0, checkpoint_seconds_ = 0, image_seconds_ = 0; // per writer
  int snapshots_ = 0, checkpoints_ = 0, image_files_ = 0;
  FieldSampler sampler_;
  PetscInt sample_every_ = 0;
};

} // namespace morphogen
