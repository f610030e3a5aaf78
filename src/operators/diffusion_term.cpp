#include "operators/diffusion_term.hpp"

#include <limits>

namespace morphogen {

DiffusionTerm::DiffusionTerm(int species, std::string name, const DiffusionOperator& op)
    : s_(species), name_(std::move(name)), op_(op) {}

std::string DiffusionTerm::describe() const {
  const char* kind = "";
  switch (op_.scheme()) {
  case DiffusionScheme::Constant:
    kind = "constant";
    break;
  case DiffusionScheme::IsotropicField:
    kind = "map";
    break;
  case DiffusionScheme::Tensor:
    kind = "tensor, second order";
    break;
  case DiffusionScheme::TensorFirstOrder:
    kind = "tensor, first order";
    break;
  }
  return "diffusion of " + name_ + " (" + kind + ")";
}

double DiffusionTerm::stable_dt() const {
  const double r = op_.radius();
  return r > 0 ? 2.0 / r : std::numeric_limits<double>::infinity();
}

void DiffusionTerm::add_rates(const StateArrays& state, double /*t*/,
                              const RateArrays& rates) const {
  const Grid& grid = op_.grid();
  const Box& ob = grid.owned();
  const double* u = state.u[static_cast<size_t>(s_)];
  if (state.stride != 1) { // the operator reads a plain ghosted array
    plain_.resize(static_cast<size_t>(grid.ghosted().size()));
    for (size_t c = 0; c < plain_.size(); ++c)
      plain_[c] = u[state.stride * static_cast<PetscInt>(c)];
    u = plain_.data();
  }
  row_.resize(static_cast<size_t>(ob.m[0]));
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
      op_.apply_row(u, grid.local_index(ob.s[0], j, k), static_cast<int>(ob.m[0]), row_.data());
      const PetscInt o = grid.owned_index(ob.s[0], j, k);
      for (PetscInt i = 0; i < ob.m[0]; ++i)
        rates.at(static_cast<size_t>(s_), o + i) += row_[static_cast<size_t>(i)];
    }
}

} // namespace morphogen
