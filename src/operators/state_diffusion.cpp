#include "operators/state_diffusion.hpp"

#include <algorithm>
#include <limits>

namespace morphogen {

StateDiffusionTerm::StateDiffusionTerm(int species, std::string name, DiffusionOperator& op,
                                       const Halo& halo, std::unique_ptr<CoefficientRule> rule)
    : DiffusionTerm(species, std::move(name), op), mop_(op), halo_(halo), rule_(std::move(rule)) {}

std::string StateDiffusionTerm::describe() const {
  std::string d = DiffusionTerm::describe();
  return d.substr(0, d.rfind('(')) + "(" + rule_->describe() + ", lagged per implicit step)";
}

double StateDiffusionTerm::stable_dt() const {
  const Grid& g = op().grid();
  double iso = 0;
  for (int d = 0; d < g.dim(); ++d)
    iso += 4.0 / (g.spec().h(d) * g.spec().h(d));
  const double r = rule_->max_eigenvalue() * iso;
  return r > 0 ? 2.0 / r : std::numeric_limits<double>::infinity();
}

bool StateDiffusionTerm::refresh(const std::vector<VecH>& u) const {
  const PetscScalar* a = nullptr;
  MG_PETSC(VecGetArrayRead(u[static_cast<size_t>(species())], &a));
  buf_.assign(a, a + op().grid().ghosted().size());
  MG_PETSC(VecRestoreArrayRead(u[static_cast<size_t>(species())], &a));
  refresh_from(buf_.data());
  return true;
}

void StateDiffusionTerm::refresh_from(const double* u) const {
  const Grid& grid = op().grid();
  const int dim = grid.dim(), nc = rule_->components();
  const size_t ng = static_cast<size_t>(grid.ghosted().size());
  if (u != buf_.data()) buf_.assign(u, u + ng);
  halo_.begin(buf_.data());
  halo_.end(buf_.data());
  halo_.fill_mirror(buf_.data(), {1.0, 1.0, 1.0});
  const long st[3] = {1, static_cast<long>(grid.ghosted().m[0]),
                      static_cast<long>(grid.ghosted().m[0] * grid.ghosted().m[1])};
  double ih[3];
  for (int d = 0; d < dim; ++d)
    ih[d] = 0.5 / grid.spec().h(d);
  // The previous step's arrays, reused (same zero start as fresh ones, no allocation per step).
  std::vector<std::vector<double>>& coef = coef_scratch_;
  coef.resize(static_cast<size_t>(nc));
  for (auto& a : coef)
    a.assign(ng, 0.0);
  const Box& ob = grid.owned();
  double g[3] = {0, 0, 0}, cv[6];
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        const PetscInt c = grid.local_index(i, j, k);
        for (int d = 0; d < dim; ++d)
          g[d] = (buf_[c + st[d]] - buf_[c - st[d]]) * ih[d];
        rule_->at(c, g, cv);
        for (int q = 0; q < nc; ++q)
          coef[q][c] = cv[q];
      }
  mop_.set_coefficients(coef, halo_);
}

} // namespace morphogen
