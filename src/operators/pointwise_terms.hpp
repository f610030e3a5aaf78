// Terms that read only their own cell (halo 0):
//   ReactionTerm  R_s(u; p(x))      the model's kinetics, parameters scalar or per cell
//   SourceTerm    S_s(x, t)         -source_<species> values (fields/source_terms.hpp)
#pragma once

#include "fields/param_set.hpp"
#include "fields/source_terms.hpp"
#include "fields/timed_params.hpp"
#include "operators/term.hpp"

#include <functional>

namespace morphogen {

class ReactionTerm : public Term {
public:
  using RatesFn = std::function<void(const double* u, const double* p, double* r)>;
  // Keeps references to grid, params and timed (null: no parameter uses t). With timed
  // parameters add_rates first evaluates them at its t (the TS stage times).
  ReactionTerm(const Grid& grid, std::string model, RatesFn rates, int nspecies, ParamSet& params,
               TimedParams* timed = nullptr);

  Kind kind() const override { return Kind::Reaction; }
  std::string describe() const override { return "reaction (" + model_ + ")"; }
  bool uses_time() const override { return timed_ && timed_->any(); }
  void add_rates(const StateArrays& state, double t, const RateArrays& rates) const override;

private:
  const Grid& grid_;
  std::string model_;
  RatesFn rates_;
  int ns_;
  ParamSet& params_;
  TimedParams* timed_;
};

class SourceTerm : public Term {
public:
  // `sources` must outlive the term (its time-dependent values are cached there).
  SourceTerm(const Grid& grid, SourceTerms& sources, std::vector<std::string> species);

  Kind kind() const override { return Kind::Source; }
  std::string describe() const override;
  bool uses_time() const override { return true; }
  void add_rates(const StateArrays& state, double t, const RateArrays& rates) const override;

private:
  const Grid& grid_;
  SourceTerms& sources_;
  std::vector<std::string> species_;
};

} // namespace morphogen
