// Runs one sweep point on a rank group: sets the point's option values in the (process-local)
// options database, builds a Simulation on the group's communicator, steps it while sampling
// cheap metrics of one species (spatial mean and standard deviation, relative change since the
// previous sample, a probe at the centre cell), then gathers the final field (2-D, or the
// middle z slice in 3-D) to the group leader, which computes the pattern metrics, the run's
// dynamics, the class and the linear stability of the point's parameters. The group writes the
// point's fields (VTKHDF, float32) to points/point_<index>.vtkhdf; the leader returns the record.
#pragma once

#include "sweep/sweep_spec.hpp"
#include "sweep/work_queue.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace morphogen::sweep {

struct SweepSettings {
  std::string dir;                // sweep output directory (-output_dir)
  std::string base_dir;           // deck directory (relative file names in values)
  std::string species;            // species the metrics are computed on ("" = the first)
  long long samples = 1000;       // time-series samples per run
  std::vector<std::string> known; // sweep_* options (not unused for the point's Options)
};

// Collective on q.group(). Returns the record on the group leader (empty elsewhere); sets
// `interrupted` (on every rank of the group) when a stop signal arrived (no record then).
nlohmann::json run_point(const SweepSpec& spec, long long p, const SweepSettings& set, WorkQueue& q,
                         bool& interrupted);

std::string point_file(long long p, const char* ext);

} // namespace morphogen::sweep
