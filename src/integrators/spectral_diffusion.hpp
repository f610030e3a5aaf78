// Exact solve of one implicit diffusion substep by a separable transform (spectral_transform.hpp:
// DFT on periodic axes, DCT-II on zero-flux axes; any number of ranks):
//
//   (I - theta c M) u_new = (I + (1 - theta) c M) u,    c = dt scale_s,
//
// where M (the species' operator matrix, operators/operator_matrices.hpp) is diagonal in the
// transform's basis when it is a constant-coefficient symmetric stencil (periodic axes: a
// circulant; zero-flux axes: the mirror ghost rule): with lambda_k its eigenvalues,
//
//   u_new = T^-1( (1 + (1 - theta) c lambda_k) / (1 - theta c lambda_k) T(u)_k ).
//
// This is the KSP solve's answer to rounding (no iteration, no tolerance). lambda is measured,
// not assumed: lambda = T(M v) / T(v) for v = T^-1(1) (so T(v) = 1 and the division is
// well-conditioned). Eligibility is checked numerically at setup: M x must equal the spectral
// product for a non-trivial x to 1e-10 relative (this rejects pinned cells, spatially varying
// coefficients, cross terms on zero-flux axes and any stencil that is not diagonal), lambda_k must
// be real and <= 0 (a dissipative symmetric operator). create() returns null and says why
// otherwise; the caller then uses KSP.
#pragma once

#include "integrators/spectral_transform.hpp"

#include <memory>
#include <petscmat.h>
#include <string>
#include <vector>

namespace morphogen {

class SpectralDiffusion {
public:
  // Null (and *why set) when M is not diagonalised by the transform on this grid.
  static std::unique_ptr<SpectralDiffusion> create(const Grid& grid, Mat M, std::string* why);
  ~SpectralDiffusion();
  SpectralDiffusion(const SpectralDiffusion&) = delete;
  SpectralDiffusion& operator=(const SpectralDiffusion&) = delete;

  // u <- (I - theta c M)^-1 (I + (1 - theta) c M) u, in place on a global Vec.
  void solve(Vec u, double c, double theta);

private:
  explicit SpectralDiffusion(std::unique_ptr<SpectralTransform> t);
  bool measure_symbol(const Grid& grid, Mat M, std::string* why);
  bool check_product(const Grid& grid, Mat M, std::string* why);
  std::unique_ptr<SpectralTransform> t_;
  std::vector<double> lambda_, gain_; // per spectral entry of this rank
  double gain_c_ = -1.0, gain_theta_ = -1.0, lmax_ = 0.0;
};

} // namespace morphogen
