#include "operators/diffusion_operator.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace morphogen {

namespace {

double iso_spectral_radius(const Grid& grid) {
  double r = 0;
  for (int d = 0; d < grid.dim(); ++d)
    r += 4.0 / (grid.spec().h(d) * grid.spec().h(d));
  return r;
}

// Sign of tensor component q under a reflection normal to axis d (off-diagonals are odd).
double reflection_sign(int dim, int q, int d) {
  for (int a = 0; a < dim; ++a)
    for (int b = a + 1; b < dim; ++b) {
      const int idx = dim == 2 ? TensorLayout<2>::index(a, b) : TensorLayout<3>::index(a, b);
      if (idx == q) return (a == d || b == d) ? -1.0 : 1.0;
    }
  return 1.0;
}

template <int Dim> double local_max_eigenvalue(const double* s) {
  return tensor_max_eigenvalue<Dim>(s);
}

} // namespace

DiffusionOperator::DiffusionOperator(const Grid& grid, const Stencil& stencil, double D)
    : grid_(grid), scheme_(DiffusionScheme::Constant), D_(D), stencil_(stencil) {
  lmax_ = D;
  radius_ = D * stencil.spectral_radius();
  iso_radius_ = iso_spectral_radius(grid);
  const PetscInt gx = grid.ghosted().m[0], gxy = gx * grid.ghosted().m[1];
  for (int t = 0; t < stencil.nterms; ++t)
    delta_.push_back(
        static_cast<long>(stencil.off[t][0] + gx * stencil.off[t][1] + gxy * stencil.off[t][2]));
}

DiffusionOperator::DiffusionOperator(const Grid& grid, const Halo& halo, DiffusionScheme scheme,
                                     std::vector<std::vector<double>> coef)
    : grid_(grid), scheme_(scheme), coef_(std::move(coef)) {
  finish_setup(halo);
}

void DiffusionOperator::finish_setup(const Halo& halo) {
  const int dim = grid_.dim();
  for (int d = 0; d < dim; ++d)
    inv_h_[d] = 1.0 / grid_.spec().h(d);
  iso_radius_ = iso_spectral_radius(grid_);
  const PetscInt gx = grid_.ghosted().m[0], gxy = gx * grid_.ghosted().m[1];
  const int nb = dim == 2 ? 9 : 27;
  delta_.assign(static_cast<size_t>(nb), 0);
  for (int t = 0; t < nb; ++t)
    delta_[t] = static_cast<long>((t % 3 - 1) + gx * ((t / 3) % 3 - 1) +
                                  (dim == 3 ? gxy * (t / 9 - 1) : 0));
  for (size_t q = 0; q < coef_.size(); ++q) {
    std::array<double, 3> sign{1, 1, 1};
    for (int d = 0; d < dim; ++d)
      sign[d] = scheme_ == DiffusionScheme::IsotropicField
                    ? 1.0
                    : reflection_sign(dim, static_cast<int>(q), d);
    halo.begin(coef_[q].data());
    halo.end(coef_[q].data());
    halo.fill_mirror(coef_[q].data(), sign);
  }
  st_[0] = 1;
  st_[1] = static_cast<long>(gx);
  st_[2] = static_cast<long>(gxy);
  if (scheme_ == DiffusionScheme::Tensor) build_dual_tensors();
  // Largest eigenvalue over the owned cells, then over the ranks.
  const Box& ob = grid_.owned();
  double lmax = 0, s[6];
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        const PetscInt c = grid_.local_index(i, j, k);
        for (size_t q = 0; q < coef_.size(); ++q)
          s[q] = coef_[q][c];
        const double l = scheme_ == DiffusionScheme::IsotropicField ? s[0]
                         : dim == 2                                 ? local_max_eigenvalue<2>(s)
                                                                    : local_max_eigenvalue<3>(s);
        lmax = std::max(lmax, l);
      }
  MPI_Allreduce(&lmax, &lmax_, 1, MPI_DOUBLE, MPI_MAX, grid_.comm());
  radius_ = lmax_ * iso_radius_;
}

void DiffusionOperator::build_dual_tensors() {
  // Dual cell with lower cell l: the mean of the tensors of cells l + {0,1}^dim; needed for
  // l from one below the owned box to its last cell on every axis.
  const int dim = grid_.dim(), nq = 1 << dim;
  const Box& ob = grid_.owned();
  dual_.assign(coef_.size(), std::vector<double>(coef_[0].size(), 0.0));
  const PetscInt k0 = dim == 3 ? ob.s[2] - 1 : ob.s[2];
  for (PetscInt k = k0; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1] - 1; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0] - 1; i < ob.s[0] + ob.m[0]; ++i) {
        const PetscInt l = grid_.local_index(i, j, k);
        for (size_t q = 0; q < coef_.size(); ++q) {
          double sum = 0;
          for (int b = 0; b < nq; ++b)
            sum += coef_[q][l + (b & 1) * st_[0] + ((b >> 1) & 1) * st_[1] +
                            (dim == 3 ? (b >> 2) * st_[2] : 0)];
          dual_[q][l] = sum / nq;
        }
        zero_flux_dual(i, j, k, l);
      }
}

void DiffusionOperator::zero_flux_dual(PetscInt i, PetscInt j, PetscInt k, PetscInt l) {
  // A dual cell that straddles a zero-flux face: the mean over its interior cells, then for
  // each straddled normal n the tangential block under n.sigma grad u = 0 (the Schur
  // complement sigma_tt - sigma_tn sigma_nt / sigma_nn) and sigma_tn = 0, so the tangential
  // flux next to the wall keeps its normal-gradient part (second order at the wall).
  const GridSpec& g = grid_.spec();
  const int dim = grid_.dim(), nq = 1 << dim, nc = static_cast<int>(coef_.size());
  const PetscInt lc[3] = {i, j, k};
  int straddle = 0;
  for (int d = 0; d < dim; ++d)
    if (g.bc[d] == Boundary::Neumann && (lc[d] == -1 || lc[d] == g.n[d] - 1)) straddle |= 1 << d;
  if (!straddle) return;
  double s[6] = {0, 0, 0, 0, 0, 0};
  int count = 0;
  for (int b = 0; b < nq; ++b) {
    bool inside = true;
    for (int d = 0; d < dim; ++d) {
      const PetscInt c = lc[d] + ((b >> d) & 1);
      if ((straddle >> d) & 1) inside = inside && c >= 0 && c < g.n[d];
    }
    if (!inside) continue;
    ++count;
    for (int q = 0; q < nc; ++q)
      s[q] += coef_[q][l + (b & 1) * st_[0] + ((b >> 1) & 1) * st_[1] +
                       (dim == 3 ? (b >> 2) * st_[2] : 0)];
  }
  for (int q = 0; q < nc; ++q)
    s[q] /= count;
  auto idx = [dim](int a, int b) {
    return dim == 2 ? TensorLayout<2>::index(a, b) : TensorLayout<3>::index(a, b);
  };
  for (int n = 0; n < dim; ++n) {
    if (!((straddle >> n) & 1)) continue;
    double t[6];
    std::copy(s, s + nc, t);
    for (int a = 0; a < dim; ++a)
      for (int b = a; b < dim; ++b)
        if (a != n && b != n)
          t[idx(a, b)] = s[idx(a, b)] - s[idx(a, n)] * s[idx(b, n)] / s[idx(n, n)];
    for (int a = 0; a < dim; ++a)
      if (a != n) t[idx(a, n)] = 0.0;
    std::copy(t, t + nc, s);
  }
  for (int q = 0; q < nc; ++q)
    dual_[q][l] = s[q];
}

bool DiffusionOperator::box() const {
  if (scheme_ == DiffusionScheme::Constant) return isotropic_box(stencil_);
  return scheme_ != DiffusionScheme::IsotropicField;
}

void DiffusionOperator::weights(PetscInt i, PetscInt j, PetscInt k, double* w) const {
  const int dim = grid_.dim();
  const int nb = dim == 2 ? 9 : 27;
  if (scheme_ == DiffusionScheme::Constant) {
    std::fill(w, w + nb, 0.0);
    for (int t = 0; t < stencil_.nterms; ++t)
      w[(stencil_.off[t][0] + 1) + 3 * (stencil_.off[t][1] + 1) +
        (dim == 3 ? 9 * (stencil_.off[t][2] + 1) : 0)] += D_ * stencil_.w[t];
    return;
  }
  const PetscInt c = grid_.local_index(i, j, k);
  const int nc = static_cast<int>(coef_.size());
  if (scheme_ == DiffusionScheme::Tensor) { // from the dual-cell tensors, as the explicit sweep
    double sq[8 * 6];
    for (int q = 0; q < (1 << dim); ++q) {
      long off = 0;
      for (int d = 0; d < dim; ++d)
        off += (((q >> d) & 1) - 1) * st_[d];
      for (int m = 0; m < nc; ++m)
        sq[q * nc + m] = dual_[m][c + off];
    }
    if (dim == 2)
      tensor_weights_dual<2>(sq, inv_h_, w);
    else
      tensor_weights_dual<3>(sq, inv_h_, w);
    return;
  }
  double cv[27 * 6];
  for (int t = 0; t < nb; ++t)
    for (int q = 0; q < nc; ++q)
      cv[t * nc + q] = coef_[q][c + delta_[t]];
  if (dim == 2)
    scheme_weights<2>(scheme_, cv, inv_h_, w);
  else
    scheme_weights<3>(scheme_, cv, inv_h_, w);
}

namespace {

// D times a constant stencil of NT terms along a row (NT fixed so the loop vectorises).
template <int NT>
void constant_row(const double* w_in, const long* delta_in, double D, const double* u, int n,
                  double* out) {
  double w[NT];
  long delta[NT];
  for (int t = 0; t < NT; ++t) {
    w[t] = w_in[t];
    delta[t] = delta_in[t];
  }
  for (int m = 0; m < n; ++m) {
    double v = 0;
    for (int t = 0; t < NT; ++t)
      v += w[t] * u[m + delta[t]];
    out[m] = D * v;
  }
}

template <int Dim>
void dispatch_row(DiffusionScheme s, int n, const double* const* coef, const long* st,
                  const double* u, const double* inv_h, double* out) {
  switch (s) {
  case DiffusionScheme::IsotropicField:
    diffusion_row<Dim, DiffusionScheme::IsotropicField>(n, coef, st, u, inv_h, out);
    break;
  case DiffusionScheme::TensorFirstOrder:
    diffusion_row<Dim, DiffusionScheme::TensorFirstOrder>(n, coef, st, u, inv_h, out);
    break;
  default:
    diffusion_row<Dim, DiffusionScheme::Tensor>(n, coef, st, u, inv_h, out);
  }
}

} // namespace

void DiffusionOperator::apply_row(const double* u, PetscInt c, int n, double* out) const {
  if (scheme_ == DiffusionScheme::Constant) {
    switch (stencil_.nterms) {
    case 5:
      constant_row<5>(stencil_.w.data(), delta_.data(), D_, u + c, n, out);
      break;
    case 7:
      constant_row<7>(stencil_.w.data(), delta_.data(), D_, u + c, n, out);
      break;
    case 9:
      constant_row<9>(stencil_.w.data(), delta_.data(), D_, u + c, n, out);
      break;
    case 19:
      constant_row<19>(stencil_.w.data(), delta_.data(), D_, u + c, n, out);
      break;
    default:
      constant_row<27>(stencil_.w.data(), delta_.data(), D_, u + c, n, out);
    }
    return;
  }
  const auto& src = scheme_ == DiffusionScheme::Tensor ? dual_ : coef_;
  const double* coef[6];
  for (size_t q = 0; q < src.size(); ++q)
    coef[q] = src[q].data() + c;
  if (grid_.dim() == 2)
    dispatch_row<2>(scheme_, n, coef, st_, u + c, inv_h_, out);
  else
    dispatch_row<3>(scheme_, n, coef, st_, u + c, inv_h_, out);
}

Stencil DiffusionOperator::mean_stencil() const {
  if (scheme_ == DiffusionScheme::Constant) {
    Stencil s = stencil_;
    for (int t = 0; t < s.nterms; ++t)
      s.w[t] *= D_;
    return s;
  }
  const int dim = grid_.dim(), nc = static_cast<int>(coef_.size());
  std::vector<double> sum(static_cast<size_t>(nc), 0.0), mean(static_cast<size_t>(nc));
  const Box& ob = grid_.owned();
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        for (int q = 0; q < nc; ++q)
          sum[q] += coef_[q][grid_.local_index(i, j, k)];
  MPI_Allreduce(sum.data(), mean.data(), nc, MPI_DOUBLE, MPI_SUM, grid_.comm());
  const int nb = dim == 2 ? 9 : 27;
  std::vector<double> cv(static_cast<size_t>(nb * nc)), w(static_cast<size_t>(nb));
  for (int t = 0; t < nb; ++t)
    for (int q = 0; q < nc; ++q)
      cv[t * nc + q] = mean[q] / static_cast<double>(grid_.global_cells());
  if (dim == 2)
    scheme_weights<2>(scheme_, cv.data(), inv_h_, w.data());
  else
    scheme_weights<3>(scheme_, cv.data(), inv_h_, w.data());
  Stencil s;
  s.name = "mean";
  for (int t = 0; t < nb; ++t)
    if (w[t] != 0.0) s.add(t % 3 - 1, (t / 3) % 3 - 1, dim == 3 ? t / 9 - 1 : 0, w[t]);
  return s;
}

} // namespace morphogen
