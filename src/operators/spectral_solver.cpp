#include "operators/spectral_solver.hpp"

#include "core/petsc_handle.hpp"

#include <algorithm>
#include <cmath>

namespace morphogen {

void fill_spectral_probe(const Grid& grid, Vec x) {
  const Box& ob = grid.owned();
  PetscScalar* a;
  MG_PETSC(VecGetArray(x, &a));
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i) {
        const double n = static_cast<double>(grid.natural_index(i, j, k));
        a[grid.owned_index(i, j, k)] = std::sin(0.7 * n + 0.3 * std::fmod(n, 7.0)) + 0.1;
      }
  MG_PETSC(VecRestoreArray(x, &a));
}

namespace {

double max_all(MPI_Comm comm, double v) {
  double r = v;
  MPI_Allreduce(&v, &r, 1, MPI_DOUBLE, MPI_MAX, comm);
  return r;
}

} // namespace

SpectralSolver::SpectralSolver(std::unique_ptr<SpectralTransform> t) : t_(std::move(t)) {}
SpectralSolver::~SpectralSolver() = default;

std::unique_ptr<SpectralSolver> SpectralSolver::create(const Grid& grid, Mat M, std::string* why) {
  return create(grid, M, why, axis_kinds(grid));
}

std::unique_ptr<SpectralSolver> SpectralSolver::create(const Grid& grid, Mat M, std::string* why,
                                                       const std::array<AxisKind, 3>& kinds) {
  std::unique_ptr<SpectralSolver> sp(
      new SpectralSolver(std::make_unique<SpectralTransform>(grid, kinds)));
  if (!sp->measure_symbol(grid, M, why) || !sp->check_product(grid, M, why)) return nullptr;
  return sp;
}

// lambda = T(M v) / T(v), v = T^-1(1); real and <= 0 (to 1e-12 of max |lambda|) or refused.
bool SpectralSolver::measure_symbol(const Grid& grid, Mat M, std::string* why) {
  SpectralTransform& t = *t_;
  const size_t n = t.entries(), w = static_cast<size_t>(t.width());
  double* sp = t.spectrum();
  for (size_t e = 0; e < n; ++e)
    for (size_t c = 0; c < w; ++c)
      sp[e * w + c] = c == 0 ? 1.0 : 0.0;
  VecH v = grid.create_global(), y = grid.create_global();
  t.backward(v);
  MG_PETSC(MatMult(M, v, y));
  t.forward(v);
  const std::vector<double> tv(sp, sp + n * w);
  t.forward(y);
  lambda_.resize(n);
  double lmax = 0.0, imax = 0.0, lpos = 0.0;
  for (size_t e = 0; e < n; ++e) {
    const double a = sp[e * w], b = w == 2 ? sp[e * w + 1] : 0.0;
    const double c = tv[e * w], d = w == 2 ? tv[e * w + 1] : 0.0, q = c * c + d * d;
    lambda_[e] = (a * c + b * d) / q;
    imax = std::max(imax, std::fabs((b * c - a * d) / q));
    lmax = std::max(lmax, std::fabs(lambda_[e]));
    lpos = std::max(lpos, lambda_[e]);
  }
  MPI_Comm comm = grid.comm();
  lmax = max_all(comm, lmax);
  imax = max_all(comm, imax);
  lpos = max_all(comm, lpos);
  if (!(lmax > 0.0) || !(imax <= 1e-12 * lmax) || !(lpos <= 1e-12 * lmax)) {
    *why = "the operator is not symmetric and dissipative in the transform's basis";
    return false;
  }
  lmax_ = lmax;
  return true;
}

// M x against T^-1(lambda T(x)) / norm for a probe x, to 1e-10 of max |lambda|.
bool SpectralSolver::check_product(const Grid& grid, Mat M, std::string* why) {
  SpectralTransform& t = *t_;
  VecH x = grid.create_global(), y = grid.create_global(), z = grid.create_global();
  fill_spectral_probe(grid, x);
  MG_PETSC(MatMult(M, x, y));
  t.forward(x);
  double* sp = t.spectrum();
  const size_t w = static_cast<size_t>(t.width());
  for (size_t e = 0; e < t.entries(); ++e)
    for (size_t c = 0; c < w; ++c)
      sp[e * w + c] *= lambda_[e] / t.norm();
  t.backward(z);
  PetscReal dnorm;
  MG_PETSC(VecAXPY(z, -1.0, y));
  MG_PETSC(VecNorm(z, NORM_INFINITY, &dnorm));
  if (!(dnorm <= 1e-10 * lmax_ * 1.5)) { // |probe| <= 1.1, so |M x| <= 1.1 lmax
    *why = "the operator is not a constant-coefficient stencil diagonal in the DFT/DCT basis "
           "(M x differs from the spectral product by " +
           std::to_string(dnorm) + ")";
    return false;
  }
  return true;
}

void SpectralSolver::solve_negated(Vec r, Vec x) {
  SpectralTransform& t = *t_;
  const size_t n = t.entries(), w = static_cast<size_t>(t.width());
  t.forward(r);
  double* sp = t.spectrum();
  const double tiny = 1e-12 * lmax_, inv_n = 1.0 / t.norm();
  for (size_t e = 0; e < n; ++e) {
    const double g = -lambda_[e] > tiny ? -inv_n / lambda_[e] : 0.0;
    for (size_t k = 0; k < w; ++k)
      sp[e * w + k] *= g;
  }
  t.backward(x);
}

void SpectralSolver::solve_shifted(Vec r, Vec x, double c, double theta) {
  SpectralTransform& t = *t_;
  const size_t n = t.entries(), w = static_cast<size_t>(t.width());
  t.forward(r);
  double* sp = t.spectrum();
  const double inv_n = 1.0 / t.norm();
  for (size_t e = 0; e < n; ++e) {
    const double g = inv_n / (1.0 - theta * c * lambda_[e]);
    for (size_t k = 0; k < w; ++k)
      sp[e * w + k] *= g;
  }
  t.backward(x);
}

void SpectralSolver::step(Vec u, double c, double theta) {
  SpectralTransform& t = *t_;
  const size_t n = t.entries(), w = static_cast<size_t>(t.width());
  if (c != gain_c_ || theta != gain_theta_) {
    gain_.resize(n);
    const double inv_n = 1.0 / t.norm();
    for (size_t e = 0; e < n; ++e)
      gain_[e] = inv_n * (1.0 + (1.0 - theta) * c * lambda_[e]) / (1.0 - theta * c * lambda_[e]);
    gain_c_ = c;
    gain_theta_ = theta;
  }
  t.forward(u);
  double* sp = t.spectrum();
  for (size_t e = 0; e < n; ++e)
    for (size_t k = 0; k < w; ++k)
      sp[e * w + k] *= gain_[e];
  t.backward(u);
}

} // namespace morphogen
