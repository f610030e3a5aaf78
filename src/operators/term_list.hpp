// The terms and constraints of a run (operators/term.hpp), with the queries the integrators
// make: the diffusion term of each species, the terms an explicit step evaluates besides
// diffusion and reaction, the halo all terms need together, and the explicit stable dt.
#pragma once

#include "operators/constraints.hpp"
#include "operators/diffusion_term.hpp"

#include <memory>

namespace morphogen {

class TermList {
public:
  void add(std::unique_ptr<Term> t) { terms_.push_back(std::move(t)); }
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
};

} // namespace morphogen
