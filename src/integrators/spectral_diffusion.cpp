#include "integrators/spectral_diffusion.hpp"

#include "core/petsc_handle.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <fftw3.h>

namespace morphogen {

// FFTW's real transforms of the grid (dims slowest first: z, y, x), planned once.
struct SpectralDiffusion::Fft {
  size_t ncell = 1, nspec = 1;
  double* real = nullptr;
  fftw_complex* spec = nullptr;
  fftw_plan fwd = nullptr, bwd = nullptr;
  Fft(int rank, const int* dims) {
    for (int d = 0; d < rank; ++d)
      ncell *= static_cast<size_t>(dims[d]);
    nspec =
        ncell / static_cast<size_t>(dims[rank - 1]) * static_cast<size_t>(dims[rank - 1] / 2 + 1);
    real = fftw_alloc_real(ncell);
    spec = fftw_alloc_complex(nspec);
    fwd = fftw_plan_dft_r2c(rank, dims, real, spec, FFTW_ESTIMATE);
    bwd = fftw_plan_dft_c2r(rank, dims, spec, real, FFTW_ESTIMATE);
  }
  ~Fft() {
    if (fwd) fftw_destroy_plan(fwd);
    if (bwd) fftw_destroy_plan(bwd);
    fftw_free(real);
    fftw_free(spec);
  }
  // spec = FFT(x) of a Vec's values; x = IFFT(spec) (unnormalised) back into a Vec.
  void forward(Vec x) {
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(x, &a));
    std::copy(a, a + ncell, real);
    MG_PETSC(VecRestoreArrayRead(x, &a));
    fftw_execute(fwd);
  }
  void backward(Vec x) {
    fftw_execute(bwd); // destroys spec
    PetscScalar* a;
    MG_PETSC(VecGetArray(x, &a));
    std::copy(real, real + ncell, a);
    MG_PETSC(VecRestoreArray(x, &a));
  }
};

namespace {

// A deterministic, non-smooth test vector (every Fourier mode present).
void fill_probe(Vec x) {
  PetscInt n;
  PetscScalar* a;
  MG_PETSC(VecGetLocalSize(x, &n));
  MG_PETSC(VecGetArray(x, &a));
  for (PetscInt i = 0; i < n; ++i)
    a[i] = std::sin(0.7 * static_cast<double>(i) + 0.3 * static_cast<double>(i % 7)) + 0.1;
  MG_PETSC(VecRestoreArray(x, &a));
}

} // namespace

SpectralDiffusion::SpectralDiffusion(std::unique_ptr<Fft> fft) : fft_(std::move(fft)) {}
SpectralDiffusion::~SpectralDiffusion() = default;

std::unique_ptr<SpectralDiffusion> SpectralDiffusion::create(const Grid& grid, Mat M,
                                                             std::string* why) {
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  if (size > 1) {
    *why = "more than one rank (the FFT solve is serial)";
    return nullptr;
  }
  const Box& ob = grid.owned();
  int dims[3], rank = grid.dim();
  for (int d = 0; d < rank; ++d)
    dims[d] = static_cast<int>(ob.m[rank - 1 - d]);
  std::unique_ptr<SpectralDiffusion> sp(new SpectralDiffusion(std::make_unique<Fft>(rank, dims)));
  Fft& f = *sp->fft_;
  // lambda = FFT(M e_0): the stencil's symbol, if M is circulant.
  VecH e = grid.create_global(), y = grid.create_global();
  MG_PETSC(VecSet(e, 0.0));
  MG_PETSC(VecSetValue(e, 0, 1.0, INSERT_VALUES));
  MG_PETSC(VecAssemblyBegin(e));
  MG_PETSC(VecAssemblyEnd(e));
  MG_PETSC(MatMult(M, e, y));
  f.forward(y);
  sp->lambda_.resize(f.nspec);
  double lmax = 0.0, imax = 0.0, lpos = 0.0;
  for (size_t k = 0; k < f.nspec; ++k) {
    sp->lambda_[k] = f.spec[k][0];
    lmax = std::max(lmax, std::fabs(f.spec[k][0]));
    imax = std::max(imax, std::fabs(f.spec[k][1]));
    lpos = std::max(lpos, f.spec[k][0]);
  }
  if (!(lmax > 0.0) || imax > 1e-12 * lmax || lpos > 1e-12 * lmax) {
    *why = "the operator is not symmetric and dissipative";
    return nullptr;
  }
  // M x against IFFT(lambda FFT(x)) / N for a probe x.
  fill_probe(e);
  MG_PETSC(MatMult(M, e, y));
  f.forward(e);
  for (size_t k = 0; k < f.nspec; ++k)
    for (int c = 0; c < 2; ++c)
      f.spec[k][c] *= sp->lambda_[k] / static_cast<double>(f.ncell);
  VecH z = grid.create_global();
  f.backward(z);
  PetscReal dnorm, ynorm;
  MG_PETSC(VecAXPY(z, -1.0, y));
  MG_PETSC(VecNorm(z, NORM_INFINITY, &dnorm));
  MG_PETSC(VecNorm(y, NORM_INFINITY, &ynorm));
  if (!(dnorm <= 1e-10 * lmax * 1.5)) { // |probe| <= 1.1, so |M x| <= 1.1 lmax
    *why = "the operator is not a periodic constant-coefficient stencil (M x differs from the "
           "FFT product by " +
           std::to_string(dnorm) + ")";
    return nullptr;
  }
  (void)ynorm;
  return sp;
}

void SpectralDiffusion::solve(Vec u, double c, double theta) {
  Fft& f = *fft_;
  if (c != gain_c_ || theta != gain_theta_) {
    gain_.resize(f.nspec);
    const double inv_n = 1.0 / static_cast<double>(f.ncell);
    for (size_t k = 0; k < f.nspec; ++k)
      gain_[k] = inv_n * (1.0 + (1.0 - theta) * c * lambda_[k]) / (1.0 - theta * c * lambda_[k]);
    gain_c_ = c;
    gain_theta_ = theta;
  }
  f.forward(u);
  for (size_t k = 0; k < f.nspec; ++k) {
    f.spec[k][0] *= gain_[k];
    f.spec[k][1] *= gain_[k];
  }
  f.backward(u);
}

} // namespace morphogen
