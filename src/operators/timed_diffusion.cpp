#include "operators/timed_diffusion.hpp"

namespace morphogen {

TimedDiffusionTerm::TimedDiffusionTerm(int species, std::string name, DiffusionOperator& op,
                                       const Halo& halo, int components, Fill fill)
    : DiffusionTerm(species, std::move(name), op), mop_(op), halo_(halo), nc_(components),
      fill_(std::move(fill)) {}

std::string TimedDiffusionTerm::describe() const {
  std::string d = DiffusionTerm::describe();
  return d.substr(0, d.size() - 1) + ", time-dependent)";
}

bool TimedDiffusionTerm::set_time(double t) const {
  if (t == last_t_) return false;
  const size_t ng = static_cast<size_t>(op().grid().ghosted().size());
  scratch_.resize(static_cast<size_t>(nc_));
  for (auto& a : scratch_)
    a.assign(ng, 0.0);
  fill_(t, scratch_);
  mop_.set_coefficients(scratch_, halo_);
  last_t_ = t;
  return true;
}

} // namespace morphogen
