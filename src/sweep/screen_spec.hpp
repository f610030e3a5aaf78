// The options of a Turing screen (`morphogen screen`, sweep/screen_main.hpp), read and checked
// before anything is computed or written:
//
//   -model NAME, -layers L, -species/-rate_S   the model, as for a run (app/model_setup.hpp)
//   -screen_params alpha,beta    the varied quantities: parameters of the model, or D_<species>
//   -screen_range_<name> lo,hi   per varied quantity, lo < hi, inside the parameter's range
//   -screen_sampling grid|random|lhs   (default grid; sweep/screen_sampling.hpp)
//   -screen_points N[,N2,...]    grid: per axis (one value: every axis), default 101;
//                                random/lhs: the number of sets, default 10000
//   -screen_seed S               random/lhs (default 1)
//   -screen_output DIR           (default screen)
//   -screen_format csv|hdf5|both  the table's file(s): turing_sets.csv and/or turing_sets.h5
//   -params_NAME, -D_S           the fixed values: numbers only (defaults: the model's)
//   -screen_general, -screen_all_states, -screen_k_samples   the analysis (screen_classify.hpp)
//   -screen_search_<species> lo,hi, -screen_search_points    the steady-state search box (others:
//                                |u_s| <= 2 max(1, |init_s|)) and starts per species (0: auto)
// A screened parameter's -params_NAME (from a model deck, say) is ignored. Every problem is a
// one-line UserError naming the option. With -help, -screen_params may be missing.
#pragma once

#include "app/model_registry.hpp"
#include "core/options.hpp"
#include "sweep/screen_classify.hpp"
#include "sweep/screen_sampling.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen::sweep {

struct ScreenSpec {
  std::shared_ptr<const ModelEntry> model;
  ScreenSampler sampler;         // names are the -screen_params entries
  std::vector<int> axis_target;  // per axis: parameter index p >= 0, or D of species -1 - s
  std::vector<double> params, D; // the fixed values (screened entries overwritten per set)
  ClassifyOptions classify;
  std::string output;
  bool csv = true, hdf5 = false; // -screen_format
};

// Collective (every rank reads the same options). Throws UserError.
ScreenSpec read_screen_spec(Options& opt);

} // namespace morphogen::sweep
