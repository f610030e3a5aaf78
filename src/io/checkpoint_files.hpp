// Checkpoint files in an output directory: checkpoint_<step, 7+ digits>.vtkhdf (a VTKHDF
// snapshot in double precision plus the /morphogen restart attributes, see app/checkpoint.hpp).
// A checkpoint is written as <name>.tmp and renamed when complete, so a file with the final name
// is complete unless it was damaged afterwards. These helpers run on one rank.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace morphogen::io {

std::string checkpoint_file_name(long long step);

// (step, path) of every checkpoint_*.vtkhdf in dir, newest (highest step) first.
std::vector<std::pair<long long, std::string>> list_checkpoints(const std::string& dir);

// Deletes all but the newest `keep` checkpoints. Returns the paths removed.
std::vector<std::string> prune_checkpoints(const std::string& dir, int keep);

// Renames checkpoints with step > `step` (an abandoned future after a restart from an older
// one) to <path>.stale (.stale1, ... if that exists), so `latest` never picks them. Returns the
// paths renamed.
std::vector<std::string> retire_checkpoints_after(const std::string& dir, long long step);

} // namespace morphogen::io
