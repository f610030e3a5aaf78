#include "operators/term_list.hpp"

#include <algorithm>
#include <stdexcept>

namespace morphogen {

std::vector<const Term*> TermList::of_kind(Term::Kind kind) const {
  std::vector<const Term*> out;
  for (const auto& t : terms_)
    if (t->kind() == kind) out.push_back(t.get());
  return out;
}

std::vector<const DiffusionTerm*> TermList::diffusion(int nspecies) const {
  std::vector<const DiffusionTerm*> out(static_cast<size_t>(nspecies), nullptr);
  for (const Term* t : of_kind(Term::Kind::Diffusion)) {
    const auto* d = dynamic_cast<const DiffusionTerm*>(t);
    if (!d || d->species() < 0 || d->species() >= nspecies || out[d->species()])
      throw std::logic_error("TermList: diffusion terms do not match the species");
    out[d->species()] = d;
  }
  for (const DiffusionTerm* d : out)
    if (!d) throw std::logic_error("TermList: a species has no diffusion term");
  return out;
}

std::vector<const DiffusionOperator*> TermList::operators(int nspecies) const {
  std::vector<const DiffusionOperator*> out;
  for (const DiffusionTerm* d : diffusion(nspecies))
    out.push_back(&d->op());
  return out;
}

std::vector<int> TermList::refresh(const std::vector<VecH>& u) const {
  std::vector<int> changed;
  if (!state_dependent_) return changed;
  for (const auto& t : terms_)
    if (t->refresh(u))
      if (const auto* d = dynamic_cast<const DiffusionTerm*>(t.get())) {
        changed.push_back(d->species());
        if (matrices_) matrices_->reassemble(d->species());
      }
  return changed;
}

bool TermList::set_time(double t, std::vector<int>* changed) const {
  bool any = false;
  if (timed_)
    for (const auto& t_ : terms_)
      if (t_->timed_coefficients() && t_->set_time(t)) {
        any = true;
        if (const auto* d = dynamic_cast<const DiffusionTerm*>(t_.get())) {
          if (changed) changed->push_back(d->species());
          if (matrices_) matrices_->reassemble(d->species());
        }
      }
  if (boundary_ && boundary_->set_time(t)) {
    any = true;
    if (matrices_)
      for (int s : matrices_->set_dirichlet(boundary_->values()))
        if (changed && std::find(changed->begin(), changed->end(), s) == changed->end())
          changed->push_back(s);
  }
  return any;
}

double TermList::stable_dt() const {
  double dt = std::numeric_limits<double>::infinity();
  for (const auto& t : terms_)
    dt = std::min(dt, t->stable_dt());
  return dt;
}

const PinnedCells* TermList::pins() const {
  for (const auto& c : constraints_)
    if (const auto* p = dynamic_cast<const PinnedCells*>(c.get())) return p;
  return nullptr;
}

PetscInt TermList::constrain(std::vector<VecH>& u) const {
  PetscInt n = 0;
  for (const auto& c : constraints_)
    n += c->apply(u);
  return n;
}

std::string TermList::describe() const {
  std::string out;
  for (const auto& t : terms_)
    out += "  term: " + t->describe() + "\n";
  for (const auto& c : constraints_)
    out += "  constraint: " + c->describe() + "\n";
  return out;
}

} // namespace morphogen
