#include "operators/pointwise_terms.hpp"

#include "core/log_events.hpp"

#include <stdexcept>

namespace morphogen {

ReactionTerm::ReactionTerm(const Grid& grid, std::string model, RatesFn rates, int nspecies,
                           ParamSet& params, TimedParams* timed)
    : grid_(grid), model_(std::move(model)), rates_(std::move(rates)), ns_(nspecies),
      params_(params), timed_(timed) {
  if (!rates_ || params_.scalar.size() != params_.field.size())
    throw std::logic_error("ReactionTerm: no rates or inconsistent parameters");
}

void ReactionTerm::add_rates(const StateArrays& state, double t, const RateArrays& rates) const {
  LogScope log_scope(log_events().reaction);
  if (timed_ && timed_->any()) timed_->set_time(params_, t);
  const size_t ns = static_cast<size_t>(ns_), np = params_.scalar.size();
  std::vector<const PetscScalar*> pf(np, nullptr);
  for (size_t q = 0; q < np; ++q)
    if (params_.field[q].get()) MG_PETSC(VecGetArrayRead(params_.field[q], &pf[q]));
  std::vector<double> u(ns), p(params_.scalar), r(ns);
  const Box& ob = grid_.owned();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
      const PetscInt c0 = grid_.local_index(ob.s[0], j, k);
      const PetscInt o0 = grid_.owned_index(ob.s[0], j, k);
      for (PetscInt i = 0; i < ob.m[0]; ++i) {
        for (size_t s = 0; s < ns; ++s)
          u[s] = state.at(s, c0 + i);
        for (size_t q = 0; q < np; ++q)
          if (pf[q]) p[q] = pf[q][o0 + i];
        rates_(u.data(), p.data(), r.data());
        for (size_t s = 0; s < ns; ++s)
          rates.at(s, o0 + i) += r[s];
      }
    }
  for (size_t q = 0; q < np; ++q)
    if (pf[q]) MG_PETSC(VecRestoreArrayRead(params_.field[q], &pf[q]));
}

SourceTerm::SourceTerm(const Grid& grid, SourceTerms& sources, std::vector<std::string> species)
    : grid_(grid), sources_(sources), species_(std::move(species)) {}

std::string SourceTerm::describe() const {
  std::string names;
  for (size_t s = 0; s < species_.size(); ++s)
    if (sources_.has(static_cast<int>(s))) names += (names.empty() ? "" : ", ") + species_[s];
  return "source (" + names + ")";
}

void SourceTerm::add_rates(const StateArrays& /*state*/, double t, const RateArrays& rates) const {
  const Box& ob = grid_.owned();
  for (size_t s = 0; s < species_.size(); ++s) {
    const double* S = sources_.at(static_cast<int>(s), t);
    if (!S) continue;
    for (PetscInt o = 0; o < ob.size(); ++o)
      rates.at(s, o) += S[o];
  }
}

} // namespace morphogen
