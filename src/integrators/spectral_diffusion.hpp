// Exact solve of one implicit diffusion substep by FFT (one rank, periodic, constant
// coefficients):
//
//   (I - theta c M) u_new = (I + (1 - theta) c M) u,    c = dt scale_s,
//
// where M (the species' operator matrix, operators/operator_matrices.hpp) is a convolution with
// one stencil on a periodic grid (a circulant matrix), so that the discrete Fourier modes are its
// eigenvectors: with lambda_k = FFT(M e_0)_k (real for a symmetric stencil),
//
//   u_new = IFFT( (1 + (1 - theta) c lambda_k) / (1 - theta c lambda_k) FFT(u)_k ).
//
// This is the KSP solve's answer to rounding (no iteration, no tolerance): two real FFTs (FFTW
// r2c/c2r, planned once) and one pass over the spectrum per species and substep.
// Eligibility is checked numerically at setup, not assumed from the options: M x must equal the
// spectral product for a non-trivial x to 1e-10 relative (this rejects non-periodic axes, pinned
// cells, spatially varying coefficients and any stencil that is not translation invariant),
// lambda_k must be real and <= 0 (a dissipative symmetric operator). create() returns null and
// says why otherwise; the caller then uses KSP.
#pragma once

#include "grid/grid.hpp"

#include <memory>
#include <petscmat.h>
#include <string>
#include <vector>

namespace morphogen {

class SpectralDiffusion {
public:
  // Null (and *why set) when M is not diagonalised by the FFT on this grid, or on > 1 rank.
  static std::unique_ptr<SpectralDiffusion> create(const Grid& grid, Mat M, std::string* why);
  ~SpectralDiffusion();
  SpectralDiffusion(const SpectralDiffusion&) = delete;
  SpectralDiffusion& operator=(const SpectralDiffusion&) = delete;

  // u <- (I - theta c M)^-1 (I + (1 - theta) c M) u, in place on a global Vec.
  void solve(Vec u, double c, double theta);

private:
  struct Fft;
  explicit SpectralDiffusion(std::unique_ptr<Fft> fft);
  std::unique_ptr<Fft> fft_;
  std::vector<double> lambda_, gain_;
  double gain_c_ = -1.0, gain_theta_ = -1.0;
};

} // namespace morphogen
