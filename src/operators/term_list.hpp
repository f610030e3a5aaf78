// The terms and constraints of a run (operators/term.hpp), with the queries the integrators
// make: the diffusion term of each species, the terms an explicit step evaluates besides
// diffusion and reaction, the halo all terms need together, and the explicit stable dt.
#pragma once

#include "operators/constraints.hpp"
#include "operators/diffusion_term.hpp"
#include "operators/operator_matrices.hpp"

#include <memory>

namespace morphogen {

class TermList {
public:
  // state_dependent: the term's coefficients follow the state (refresh() recomputes them).
  void add(std::unique_ptr<Term> t, bool state_dependent = false) {
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
};

} // namespace morphogen
