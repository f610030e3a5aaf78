#include "operators/polar_diffusion.hpp"

#include <algorithm>
#include <sstream>

namespace morphogen {

namespace {

double owned_max(const Grid& grid, const std::vector<double>& a, int stride, int n) {
  const Box& ob = grid.owned();
  double m = 0;
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        for (int q = 0; q < n; ++q)
          m = std::max(m, a[static_cast<size_t>(stride * grid.local_index(i, j, k) + q)]);
  double all = 0;
  MPI_Allreduce(&m, &all, 1, MPI_DOUBLE, MPI_MAX, grid.comm());
  return all;
}

} // namespace

PolarRule::PolarRule(const Grid& grid, const PolarLobes& lobes, std::vector<double> D,
                     std::vector<double> theta0)
    : lobes_(lobes), D_(std::move(D)), theta0_(std::move(theta0)) {
  lmax_ = owned_max(grid, D_, 1, 1) * lobes_.max();
}

std::string PolarRule::describe() const {
  std::ostringstream m;
  m << "polar a(theta), " << (lobes_.witkin_kass ? "Witkin-Kass" : "cosine") << " " << lobes_.j
    << " lobes, speeds";
  for (int n = 0; n < (lobes_.witkin_kass ? 2 : lobes_.j); ++n)
    m << (n ? "," : " ") << lobes_.a[n];
  return m.str();
}

ShapedRule::ShapedRule(const Grid& grid, DiffusionScheme scheme, std::vector<double> frame,
                       std::vector<double> l, std::vector<double> D, std::vector<double> v,
                       double I)
    : dim_(grid.dim()), scheme_(scheme), frame_(std::move(frame)), l_(std::move(l)),
      D_(std::move(D)), v_(std::move(v)), I_(I) {
  // lambda_max <= D max_n l_n + D I.
  std::vector<double> dl(D_.size());
  for (size_t c = 0; c < D_.size(); ++c) {
    double m = 0;
    for (int n = 0; n < dim_; ++n)
      m = std::max(m, l_[c * static_cast<size_t>(dim_) + static_cast<size_t>(n)]);
    dl[c] = m + D_[c] * I_;
  }
  lmax_ = owned_max(grid, dl, 1, 1);
}

std::string ShapedRule::describe() const {
  std::ostringstream m;
  m << "gradient-shaped tensor, I = " << I_;
  return m.str();
}

void ShapedRule::at(PetscInt c, const double* g, double* coef) const {
  const size_t d = static_cast<size_t>(dim_);
  const double* v = v_.data() + d * static_cast<size_t>(c);
  const double dl = D_[c] * (dim_ == 2 ? shaped_dlambda<2>(g, v, I_) : shaped_dlambda<3>(g, v, I_));
  double l[3] = {0, 0, 0};
  for (size_t n = 0; n < d; ++n)
    l[n] = l_[d * static_cast<size_t>(c) + n];
  l[0] += dl;
  l[1] -= dl;
  const auto* e = reinterpret_cast<const double(*)[3]>(frame_.data() + 9 * static_cast<size_t>(c));
  if (dim_ == 2)
    principal_tensor<2>(e, l, coef);
  else
    principal_tensor<3>(e, l, coef);
}

} // namespace morphogen
