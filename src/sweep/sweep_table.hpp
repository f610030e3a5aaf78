// The sweep's tables, assembled by one rank from every points/point_<i>.json present (so a
// resumed or chunked sweep lists all finished points, whichever run computed them):
//   sweep.csv   one row per finished point (csv_header in point_record.hpp)
//   sweep.json  {"axes": [{"option", "values"}], "points": total, "finished": n,
//                "classes": {class: count}, "records": [the point records without series],
//                "stability_map": linear stability on a 4x finer grid of the axes (when every
//                axis is a model parameter params_<p> or a diffusion coefficient D_<s>):
//                {"axes": [[values]...], "turing": [...], "hopf": [...],
//                 "wavelength": [...]} flattened with the first axis fastest}
// Both are written under a temporary name and renamed.
#pragma once

#include "sweep/sweep_spec.hpp"

#include <mpi.h>
#include <nlohmann/json.hpp>

#include <string>

namespace morphogen::sweep {

// The stability map of sweep.json (above; null when there is none, {"error": ...} when its set-up
// fails). Collective on comm: the points are shared among its ranks; the map is returned on
// rank 0 (null elsewhere). base_dir: the deck's directory (relative file names in values).
nlohmann::json stability_map(const SweepSpec& spec, const std::string& base_dir, MPI_Comm comm);

// Returns "" or the error. base_options: the first point's options as YAML (for the record);
// map: stability_map's result. Chunks writing at the same time serialise on dir/.sweep.lock
// (flock).
std::string write_sweep_table(const std::string& dir, const SweepSpec& spec,
                              const std::string& base_options, nlohmann::json map);

} // namespace morphogen::sweep
