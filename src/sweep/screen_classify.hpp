// One parameter set of a Turing screen (`morphogen screen`, sweep/screen_main.hpp): its
// homogeneous steady state(s), the Jacobian there, and the verdict
//
//   NoSteadyState        the model claims none and the search finds none (or u*, J not finite)
//   UnstableHomogeneous  every steady state is unstable (or marginal) at k = 0
//   Stable               a state is stable at k = 0 and no stable state is Turing-unstable
//   Turing               a state is stable at k = 0 and unstable at some k > 0
//
// with the fastest-growing wavenumber k (continuous Laplacian, isotropic D), the wavelength
// 2 pi / k in the model's length units and the growth rate, as analysis/linear_stability.hpp
// defines them (tol = zero_tol * ||J||_inf).
//
// States: the model's steady_state; when it claims none, or with all_states, every state
// analysis::find_steady_states finds (box and starts from `search`); the first Turing-unstable
// one (in find_steady_states' order) is reported.
// Eigenvalues: 2 species with D > 0 take the closed form of analysis/turing_2x2.hpp (no k scan;
// the fast path); otherwise (N species, a zero D, or `general`) analysis::analyse_jacobian
// samples k_samples wavenumbers on [0, 3 sqrt(||J||_inf / min positive D)] (which holds every
// unstable k when every D > 0: Gershgorin) and refines the best by golden section, so a band
// narrower than the sample spacing can be missed.
// Pure: no MPI or PETSc; the fast path does not allocate.
#pragma once

#include "analysis/linear_stability.hpp"
#include "models/model_info.hpp"

#include <vector>

namespace morphogen::sweep {

enum class Verdict { NoSteadyState, UnstableHomogeneous, Stable, Turing };

struct ClassifyOptions {
  bool general = false;    // analyse_jacobian even for 2 species
  bool all_states = false; // search every steady state even where the model gives one
  int k_samples = 256;     // the general path's samples of the dispersion curve
  double zero_tol = 1e-9;
  analysis::SteadySearch search;
};

struct SetResult {
  Verdict verdict = Verdict::NoSteadyState;
  std::vector<double> u; // the reported state (Turing: the unstable one), nspecies values
  double k = 0, wavelength = 0, growth = 0; // fastest mode (Turing only)
};

// params: entry.nparams values; D: entry.nspecies. `out` is reused between calls (its u keeps
// its capacity).
void classify_set(const ModelInfo& entry, const std::vector<double>& params,
                  const std::vector<double>& D, const ClassifyOptions& opt, SetResult& out);

} // namespace morphogen::sweep
