// What a run writes while it steps, and when it stops early:
//  - VTKHDF snapshots (float32/64) every -snapshot_every steps / -snapshot_every_time, and the
//    final state, with the <name>.vtkhdf.series and <name>.xmf indexes;
//  - checkpoints (float64 + /morphogen restart attributes) every -checkpoint_every steps,
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

namespace morphogen {

constexpr int kExitResubmit = 3; // checkpointed on a signal or the wall-time budget
constexpr int kExitWriteFailed = 4;

class RunOutput {
public:
  // wall_start: MPI_Wtime() when the program started (for -max_walltime).
  RunOutput(MPI_Comm comm, const Options& opt, double wall_start);

  // Start writing for a (new level's) simulation. restart_step < 0: a fresh run (checkpoints
  // of an earlier run in the directory are retired, the series starts empty); otherwise the run
  // continues from that step (later checkpoints are retired, later series entries dropped).
  void begin(Simulation& sim, long long restart_step, PetscInt end_step);
  // After every step. Returns true when the run must stop (a checkpoint has been written).
  bool after_step(Simulation& sim);
  // Final snapshot and checkpoint of the last level, and summary.json: per species the pattern
  // class and metrics (with the run's dynamics from samples taken every 1/1000 of the run),
  // and the linear stability of the parameters.
  void finish(Simulation& sim);

  const std::string& last_checkpoint() const { return last_checkpoint_; }
  const std::string& stop_reason() const { return stop_reason_; }

private:
  void write_snapshot(Simulation& sim);
  void write_checkpoint(Simulation& sim);
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
  double next_snapshot_time_ = 0, next_checkpoint_time_ = 0;
  long long last_snapshot_step_ = -1, last_checkpoint_step_ = -1;
  std::string last_checkpoint_, stop_reason_;
  FieldSampler sampler_;
  PetscInt sample_every_ = 0;
};

} // namespace morphogen
