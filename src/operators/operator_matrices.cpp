#include "operators/operator_matrices.hpp"

#include <cmath>

namespace morphogen {

OperatorMatrices::OperatorMatrices(const Grid& grid, const Halo& halo, const Stencil& stencil,
                                   const std::vector<const DiffusionOperator*>& ops,
                                   const std::vector<FaceValues>* dirichlet)
    : grid_(grid), halo_(halo), ops_(ops) {
  const int ns = static_cast<int>(ops.size());
  has_dirichlet_ = dirichlet != nullptr && !dirichlet->empty();
  if (has_dirichlet_) dirichlet_ = *dirichlet;
  const std::vector<FaceValues>* dir = has_dirichlet_ ? dirichlet : nullptr;
  std::shared_ptr<LaplacianMatrix> shared;
  for (int s = 0; s < ns; ++s) {
    const DiffusionOperator& op = *ops[s];
    symmetric_.push_back(op.symmetric());
    if (op.constant()) {
      if (!shared) shared = std::make_shared<LaplacianMatrix>(grid, halo, stencil, ns, dir);
      mat_.push_back(shared);
      index_.push_back(s);
      scale_.push_back(op.D());
      continue;
    }
    mat_.push_back(own_matrix(s));
    index_.push_back(0);
    scale_.push_back(1.0);
  }
  keep_pattern_.assign(static_cast<size_t>(ns), false);
  pinned_M_.resize(static_cast<size_t>(ns));
  pinned_b_.resize(static_cast<size_t>(ns));
  pin_rows_.resize(static_cast<size_t>(ns));
  pin_values_.resize(static_cast<size_t>(ns));
}

std::shared_ptr<LaplacianMatrix> OperatorMatrices::own_matrix(int s) const {
  const DiffusionOperator& op = *ops_[s];
  const int nb = grid_.dim() == 2 ? 9 : 27;
  std::vector<FaceValues> own;
  if (has_dirichlet_ && !dirichlet_.empty()) own.push_back(dirichlet_[s]);
  // With keep: the star (isotropic maps) or the whole box (tensors), zeros included.
  const bool keep = keep_pattern_.size() > static_cast<size_t>(s) && keep_pattern_[s];
  const bool box = op.box();
  auto terms = [&op, nb, keep, box](PetscInt i, PetscInt j, PetscInt k,
                                    std::vector<LaplacianMatrix::CellTerm>& out) {
    double w[27];
    op.weights(i, j, k, w);
    for (int t = 0; t < nb; ++t)
      if (w[t] != 0.0 || (keep && (box || std::abs(t % 3 - 1) + std::abs((t / 3) % 3 - 1) +
                                                  (nb == 27 ? std::abs(t / 9 - 1) : 0) <=
                                              1)))
        out.push_back({{t % 3 - 1, (t / 3) % 3 - 1, nb == 27 ? t / 9 - 1 : 0}, w[t]});
  };
  return std::make_shared<LaplacianMatrix>(grid_, halo_, terms, 1, own.empty() ? nullptr : &own);
}

void OperatorMatrices::reassemble(int s) {
  if (ops_[s]->constant()) return;
  mat_[s] = own_matrix(s);
  if (pinned_M_[s]) {
    pinned_M_[s].reset();
    pinned_b_[s].reset();
    const auto rows = pin_rows_[s];
    const auto values = pin_values_[s];
    pin(s, rows, values);
  }
}

void OperatorMatrices::keep_pattern(int s) {
  if (ops_[s]->constant() || keep_pattern_[s]) return;
  keep_pattern_[s] = true;
  reassemble(s);
}

std::vector<int> OperatorMatrices::set_dirichlet(const std::vector<FaceValues>& dirichlet) {
  std::vector<int> renewed;
  if (!has_dirichlet_ || dirichlet_.empty()) return renewed;
  dirichlet_ = dirichlet;
  const LaplacianMatrix* shared_done = nullptr;
  for (int s = 0; s < nspecies(); ++s) {
    if (ops_[s]->constant()) {
      if (mat_[s].get() != shared_done) mat_[s]->set_dirichlet(dirichlet_);
      shared_done = mat_[s].get();
    } else {
      mat_[s]->set_dirichlet({dirichlet_[s]});
    }
  }
  for (int s = 0; s < nspecies(); ++s)
    if (pinned_M_[s]) { // the coupling to the held values is redone on the new b_s
      pinned_M_[s].reset();
      pinned_b_[s].reset();
      const auto rows = pin_rows_[s];
      const auto values = pin_values_[s];
      pin(s, rows, values);
      renewed.push_back(s);
    }
  return renewed;
}

void OperatorMatrices::pin(int s, const std::vector<PetscInt>& rows,
                           const std::vector<double>& values) {
  pin_rows_[s] = rows;
  pin_values_[s] = values;
  MatH M;
  MG_PETSC(MatDuplicate(this->M(s), MAT_COPY_VALUES, M.out()));
  MG_PETSC(MatSetOption(M, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE));
  VecH x, c;
  MG_PETSC(MatCreateVecs(M, x.out(), c.out()));
  MG_PETSC(VecSet(x, 0.0));
  MG_PETSC(VecSet(c, 0.0));
  const PetscInt n = static_cast<PetscInt>(rows.size());
  MG_PETSC(VecSetValues(x, n, rows.data(), values.data(), INSERT_VALUES));
  MG_PETSC(VecAssemblyBegin(x));
  MG_PETSC(VecAssemblyEnd(x));
  // c_i = -sum_p M_ip x_p off the pinned rows, 0 on them (diag 0).
  MG_PETSC(MatZeroRowsColumns(M, n, rows.data(), 0.0, x, c));
  MG_PETSC(VecScale(c, -1.0));
  if (has_dirichlet_) {
    MG_PETSC(VecAXPY(c, 1.0, b(s)));
    const std::vector<double> zeros(rows.size(), 0.0);
    MG_PETSC(VecSetValues(c, n, rows.data(), zeros.data(), INSERT_VALUES));
    MG_PETSC(VecAssemblyBegin(c));
    MG_PETSC(VecAssemblyEnd(c));
  }
  pinned_M_[static_cast<size_t>(s)] = std::move(M);
  pinned_b_[static_cast<size_t>(s)] = std::move(c);
  has_dirichlet_ = true;
}

} // namespace morphogen
