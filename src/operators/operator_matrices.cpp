#include "operators/operator_matrices.hpp"

namespace morphogen {

OperatorMatrices::OperatorMatrices(const Grid& grid, const Halo& halo, const Stencil& stencil,
                                   const std::vector<const DiffusionOperator*>& ops,
                                   const std::vector<FaceValues>* dirichlet) {
  const int ns = static_cast<int>(ops.size());
  has_dirichlet_ = dirichlet != nullptr && !dirichlet->empty();
  const std::vector<FaceValues>* dir = has_dirichlet_ ? dirichlet : nullptr;
  std::shared_ptr<LaplacianMatrix> shared;
  const int nb = grid.dim() == 2 ? 9 : 27;
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
    std::vector<FaceValues> own;
    if (dir) own.push_back((*dir)[s]);
    auto terms = [&op, nb](PetscInt i, PetscInt j, PetscInt k,
                           std::vector<LaplacianMatrix::CellTerm>& out) {
      double w[27];
      op.weights(i, j, k, w);
      for (int t = 0; t < nb; ++t)
        if (w[t] != 0.0)
          out.push_back({{t % 3 - 1, (t / 3) % 3 - 1, nb == 27 ? t / 9 - 1 : 0}, w[t]});
    };
    mat_.push_back(std::make_shared<LaplacianMatrix>(grid, halo, terms, 1, dir ? &own : nullptr));
    index_.push_back(0);
    scale_.push_back(1.0);
  }
}

} // namespace morphogen
