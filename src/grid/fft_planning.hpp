// How the spectral transforms' FFTW plans are chosen (process-wide, as FFTW's planner and its
// wisdom are):
//
//   effort  estimate: FFTW_ESTIMATE, plans from heuristics - the same plan in every run, no
//                     wisdom read or written (bitwise-reproducible without a file);
//           measure:  FFTW_MEASURE (default) - candidate algorithms are timed once per shape;
//                     3-13x faster transforms than estimate on batched rows and strided columns;
//           patient:  FFTW_PATIENT - more candidates, much longer planning.
//   wisdom  a file of FFTW wisdom (empty: none). Read before the first plan of a process; the
//           plans a run had to time are merged into it (under flock, written to a temporary file
//           and renamed) and re-created from it on every rank, so this run and every later run
//           on this machine use exactly the same plans: runs and restarts stay bitwise
//           reproducible. An unreadable file is ignored, an
//           unwritable one gives a warning once.
#pragma once

#include <mpi.h>
#include <string>

namespace morphogen {

enum class FftEffort { Estimate, Measure, Patient };

struct FftPlanning {
  FftEffort effort = FftEffort::Measure;
  std::string wisdom; // path, or empty
};

// The default wisdom file: $XDG_CACHE_HOME/morphogen/fftw_wisdom, else
// $HOME/.cache/morphogen/fftw_wisdom, else none.
std::string default_fft_wisdom_path();

void set_fft_planning(const FftPlanning& p);
const FftPlanning& fft_planning();

// FFTW planner flags of the current effort.
unsigned fft_planner_flags();
// Before planning: read the wisdom file (once per process and path; not for estimate).
void fft_wisdom_load();
// After planning, collective over comm: when a rank had to time a plan, merge every rank's new
// wisdom into the file and give every rank the merged wisdom; true when the caller must then plan
// again (from that wisdom, without timing), so that even this run uses the file's plans.
bool fft_wisdom_sync(MPI_Comm comm);

} // namespace morphogen
