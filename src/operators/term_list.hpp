// The terms and constraints of a run (operators/term.hpp), with the queries the integrators
// make: the diffusion term of each species, the terms an explicit step evaluates besides
// diffusion and reaction, the halo all terms need together, and the explicit stable dt.
#pragma once

#include "operators/constraints.hpp"
#include "operators/diffusion_term.hpp"
#include "operators/operator_matrices.hpp"

#include "fields/dirichlet_values.hpp"

#include <memory>

namespace morphogen {

class TermList {
public:
  // state_dependent: the term's coefficients follow the state (refresh() recomputes them).
  void add(std::unique_ptr<Term> t, bool state_dependent = false) {
    timed_ = timed_ || t->timed_coefficients();
    terms_.push_back(std::move(t));
    state_dependent_ = state_dependent_ || state_dependent;
  }
  void add(std::unique_ptr<Constraint> c) { constraints_.push_back(std::move(c)); }

  const std::vector<std::unique_ptr<Term>>& terms() const { return terms_; }
  const std::vector<std::unique_ptr<Constraint>>& constraints() const { return constraints_; }
  // Terms of one kind, in list order.
  std::vector<const Term*> of_kind(Term::Kind kind) const;
  // The diffusion term of each species, by species index (size nspecies; throws if one is
  // missing or repeated).
  std::vector<const DiffusionTerm*> diffusion(int nspecies) const;
  // The diffusion operators of the species, by species index.
  std::vector<const DiffusionOperator*> operators(int nspecies) const;
  // The union of the halos of the terms selected by `pick`.
  template <class Pick> HaloNeed halo(Pick pick) const {
    HaloNeed h;
    for (const auto& t : terms_)
      if (pick(*t)) {
        h.width = std::max(h.width, t->halo().width);
        h.box = h.box || t->halo().box;
      }
    return h;
  }
  // Recompute the solution-dependent coefficients from u (Term::refresh); the matrices given to
  // use_matrices (if any) are re-assembled for the species whose operator changed. Returns
  // those species. Collective.
  std::vector<int> refresh(const std::vector<VecH>& u) const;
  // The run's assembled operators (split, TS), kept in step with refresh(); null: none.
  void use_matrices(OperatorMatrices* m) { matrices_ = m; }
  // True when some term has solution-dependent coefficients.
  bool any_state_dependent() const { return state_dependent_; }
  // Dirichlet values that may depend on t (kept by reference; set_time re-evaluates them).
  void use_boundary(DirichletValues* b) { boundary_ = b && b->time_dependent() ? b : nullptr; }
  // True when some coefficient or boundary value depends on t.
  bool any_time_dependent() const { return timed_ || boundary_; }
  // Some diffusion or other coefficient follows t (Dirichlet values alone do not count: they
  // change the matrices' b, not the matrices).
  bool any_timed_coefficients() const { return timed_; }
  // Evaluate the time-dependent coefficients (Term::set_time) and Dirichlet values at t; the
  // matrices given to use_matrices (if any) follow: re-assembled for the species whose
  // operator changed (appended to `changed` when given), their Dirichlet vectors b_s
  // recomputed. Returns true when anything changed. Nothing happens (and nothing is spent) in
  // runs without t. Collective.
  bool set_time(double t, std::vector<int>* changed = nullptr) const;
  // Largest stable forward-Euler dt of the diffusion terms (min over terms). Collective.
  double stable_dt() const;
  // The pinned-cells constraint, or null.
  const PinnedCells* pins() const;
  // Apply every constraint; returns the values changed on this rank.
  PetscInt constrain(std::vector<VecH>& u) const;
  // One line per term and constraint (for the run's banner and -help).
  std::string describe() const;

private:
  std::vector<std::unique_ptr<Term>> terms_;
  std::vector<std::unique_ptr<Constraint>> constraints_;
  OperatorMatrices* matrices_ = nullptr;
  bool state_dependent_ = false;
  bool timed_ = false;
  DirichletValues* boundary_ = nullptr;
};

} // namespace morphogen
