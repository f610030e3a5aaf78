// The frames (file, time) of an advection velocity read from files, -velocity_file TEXT:
//   PATH.series (or .vtkhdf.series)  a ParaView file-series JSON file
//                  {"files": [{"name": "a.vtkhdf", "time": 0}, ...]}, names relative to the
//                  series file's directory (what morphogen writes beside its snapshots);
//   A,B,C          a comma list of files; their times from -velocity_times T1,T2,.. (one per
//                  file) or else from a numeric attribute in each file,
//                  -velocity_time_attribute /object/name (default /morphogen/time, the time of
//                  a morphogen snapshot);
//   PATTERN        a printf integer pattern (flow_%04d.h5): the files for 0, 1, 2, ... (from 1
//                  when 0 is missing) up to the first missing index, then as a comma list;
//   PATH           one file: a steady velocity.
// Relative paths are looked up in the deck's directory first, then the working directory.
// Times must be finite and strictly increasing. Bad input is a one-line UserError naming the
// option and the value.
#pragma once

#include "core/options.hpp"

#include <string>
#include <vector>

namespace morphogen {

struct VelocityFrame {
  std::string path; // resolved path
  std::string name; // as given (messages)
  double time = 0;
};

// Collective: rank 0 reads the series file / attributes, the frames are broadcast. Reads
// -velocity_times and -velocity_time_attribute (comma lists only; refused otherwise).
std::vector<VelocityFrame> read_velocity_frames(MPI_Comm comm, Options& opt,
                                                const std::string& given,
                                                const std::string& base_dir);

// Index lo and weight w of time t between frames: u(t) = (1 - w) u_lo + w u_{lo+1}, w in
// [0, 1); before the first frame and after the last the end frame is held (w = 0).
struct FrameBracket {
  size_t lo = 0;
  double w = 0;
};
FrameBracket bracket_time(const std::vector<VelocityFrame>& frames, double t);

} // namespace morphogen
