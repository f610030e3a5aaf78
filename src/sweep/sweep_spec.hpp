// A parameter sweep: one to three axes, each an option of the base deck (usually a model
// parameter, params_<p>, or a diffusion coefficient, D_<s>) with a list of values:
//
//   sweep:                                   # deck keys, or -sweep_axes / -sweep_<option>
//     axes: [params_F, params_k]
//     params_F: linspace(0.01, 0.07, 16)     # or logspace(a, b, n), range(a, b, step),
//     params_k: [0.045, 0.05, 0.055, 0.06]   # or an explicit list
//
// Points are the Cartesian product, numbered with the first axis fastest:
//   p = i0 + n0 (i1 + n1 i2).
// A listed sweep (-sweep_points, point_list.hpp) instead takes point p from row p of a file:
// value p of every axis.
// A sweep may be split into chunks (job arrays): chunk c of C holds the points p with
// p mod C == c, so every chunk gets a similar mix of cheap and expensive points.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace morphogen::sweep {

struct Axis {
  std::string option;              // option name without '-', e.g. params_F
  std::vector<std::string> values; // as passed to the option
  std::vector<double> numbers;     // the same values as numbers
};

struct SweepSpec {
  std::vector<Axis> axes;
  bool listed = false;           // point p = value p of every axis
  std::string points_file;       // listed: the file read
  std::vector<long long> source; // listed: each point's index in that file
  long long points() const;
  // Axis indices of point p.
  std::vector<long long> indices(long long p) const;
  // (option, value) pairs of point p.
  std::vector<std::pair<std::string, std::string>> assignment(long long p) const;
  // The axis values of point p as numbers.
  std::vector<double> numbers(long long p) const;
};

// Parses "linspace(a, b, n)", "logspace(a, b, n)" (10^a .. 10^b), "range(a, b, step)" (b
// excluded) or "v1,v2,...". Throws UserError naming `key` on bad input. Values are formatted
// with 17 significant digits where computed.
std::vector<std::string> parse_axis_values(const std::string& key, const std::string& text);

} // namespace morphogen::sweep
