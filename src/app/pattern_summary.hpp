// What a run's pattern is, for summary.json and for sweep records:
//  - FieldSampler: cheap metrics of every species sampled during the run (spatial mean and
//    standard deviation, RMS change per cell since the previous sample, the value at the cell
//    (nx/3, ny/3, nz/3)), one allreduce per sample;
//  - classify_species: the final field of one species (2-D, or the middle z slice in 3-D)
//    gathered to one rank, its pattern metrics (analysis/pattern_metrics.hpp), the run's dynamics
//    from the samples (analysis/time_series.hpp) and the class (analysis/classify.hpp);
//  - stability_record: linear (Turing/Hopf) stability of the run's parameters (spatial means
//    where they vary) on its grid (analysis/linear_stability.hpp), with the fastest-growing
//    wavelength the grid allows.
// JSON has no infinities or NaN: such values are stored as null.
#pragma once

#include "analysis/linear_stability.hpp"
#include "analysis/time_series.hpp"
#include "app/simulation.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace morphogen {

class FieldSampler {
public:
  // only >= 0: sample that species alone (the others' samples stay empty).
  explicit FieldSampler(int only = -1) : only_(only) {}
  // Collective: appends one sample of every species (or of `only`).
  void take(Simulation& sim);
  const analysis::RunSamples& samples(int species) const { return samples_[species]; }
  size_t count() const { return samples_.empty() ? 0 : samples_[only_ >= 0 ? only_ : 0].t.size(); }

private:
  std::vector<analysis::RunSamples> samples_;
  std::vector<std::vector<double>> prev_;
  int only_ = -1;
};

// Collective. On rank 0: {"class", "reason", "metrics", "dynamics"}; elsewhere null.
// samples may be null (class from the final field only). diverged: the run's NaN message
// (class blowup). It is gather_species_slice to rank 0, then classify_slice there.
nlohmann::json classify_species(Simulation& sim, int species, const analysis::RunSamples* samples,
                                const std::string& diverged = "");

// Collective: the field classify_species classifies (2-D, or the middle z slice in 3-D), nx*ny
// values on rank `root`, empty elsewhere.
std::vector<double> gather_species_slice(Simulation& sim, int species, int root);

// Not collective: classify_species's result for a gathered field.
nlohmann::json classify_slice(const Simulation& sim, const std::vector<double>& field,
                              const analysis::RunSamples* samples, const std::string& diverged);

// Collective. Parameters that vary in space are analysed at their spatial means (listed in
// "parameters_averaged").
nlohmann::json stability_record(const Simulation& sim);

nlohmann::json samples_json(const analysis::RunSamples& s);

// The run's cost and provenance for summary.json: wall time (seconds since the program
// started), the time-stepping rate (cell-updates per second of the time loop), the rank count
// and the versions of morphogen, PETSc and HDF5.
nlohmann::json run_record(double wall_seconds, double cell_updates, double loop_seconds, int ranks);

// Linear stability of (params, D): every homogeneous steady state that find_steady_states
// finds, plus the model's own, is analysed; the one reported is the first Turing-unstable
// state, else the first with a Hopf instability, else the model's own steady state (so a
// multistable model like Gray-Scott reports the pattern-forming branch). states: how many.
analysis::StabilityResult analyse_states(const ModelEntry& model, const std::vector<double>& params,
                                         const std::vector<double>& D,
                                         const analysis::StabilityOptions& so, int* states);

} // namespace morphogen
