// A sweep over a list of points (-sweep_points FILE) instead of the product of the axes' values:
// one point per data row of a CSV file whose first line names the columns, or of an HDF5 table
// (io/h5_table.hpp), e.g. the Turing-unstable sets a screen wrote (turing_sets.csv or .h5), so
// a sweep simulates only those.
//
// Columns: an axis (an option, e.g. params_alpha or D_b) takes the column of its own name or,
// for params_<p>, the column <p>. Without -sweep_axes the file must be a screen's
// (index,<varied...>,wavelength,...): its varied columns become the axes (D_<s> as is, any
// other name p as params_<p>). Other columns are ignored; a column "index" is kept as each
// point's source index (otherwise the data row, from 0).
//
// -sweep_points_max N: at most N points, the rows floor(i M / N), i = 0..N-1, of M data rows.
#pragma once

#include "sweep/sweep_spec.hpp"

#include <string>
#include <vector>

namespace morphogen {
class Simulation;
}

namespace morphogen::sweep {

// Reads `path` (as given in option `key`) into a listed SweepSpec. UserError naming the key,
// the file and the line on any problem.
SweepSpec read_point_list(const std::string& key, const std::string& path,
                          const std::vector<std::string>& axes, long long max_points);

// When the points file is a screen's table (screen.json beside it names it): how the model and
// the fixed parameters and diffusion coefficients of `sim` (a point of the sweep) differ from
// the screen's (a sweep of a screen's sets with other fixed values tests other systems).
std::vector<std::string> screen_mismatches(const SweepSpec& spec, const Simulation& sim);

} // namespace morphogen::sweep
