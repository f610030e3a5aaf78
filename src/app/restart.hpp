// Restart from a checkpoint (-restart PATH, or -restart latest: the newest complete checkpoint
// in -output_dir; with none there, the run starts from its initial condition).
//
// A checkpoint is accepted when HDF5 opens it (a truncated file is not), it is VTKHDF ImageData
// with every species of the model and a /morphogen group with complete = 1, time, step and
// level, every attribute is in range (time finite >= 0, dt finite > 0, step >= 0, level in
// [0, 7], nranks >= 1, seed >= 0, origin finite, spacing finite > 0; else a UserError naming the
// file and the attribute, also with `latest`), and its model, extents and spacing match this
// run's level, and it has the fluid's state exactly when the run has -fluid (check_restart_grid).
// With `latest`, unusable
// newer files are skipped with a warning; a PATH that is unusable is an error (exit 1). The
// fields load on any number of ranks (PETSc's HDF5 viewer reads each rank's hyperslab).
#pragma once

#include "app/simulation.hpp"
#include "io/vtkhdf_file.hpp"

#include <optional>
#include <string>

namespace morphogen {

struct RestartPoint {
  std::string path;
  io::ImageInfo info;
  long long step = 0;
  double time = 0;
  int level = 0;
};

// Collective. nullopt when spec is "latest" and the directory holds no checkpoint.
std::optional<RestartPoint> locate_restart(MPI_Comm comm, const std::string& spec,
                                           const std::string& dir, const ModelEntry& model);

// UserError (identical on every rank) if the checkpoint's extents or spacing differ from sim's,
// or its fluid state does not fit sim's -fluid: a -fluid run needs a checkpoint with the flow
// (/morphogen attribute fluid and the datasets velocity_x, velocity_y, fluid_pressure), a run
// without -fluid refuses a checkpoint that has one.
void check_restart_grid(const Simulation& sim, const RestartPoint& rp);

// Collective. Checks the checkpoint against sim's grid and fluid (UserError if it does not
// match), loads the fields (and the fluid's state) and sets the clock.
void restore(Simulation& sim, const RestartPoint& rp);

} // namespace morphogen
