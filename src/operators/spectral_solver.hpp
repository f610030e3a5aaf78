// Exact solves with a constant-coefficient stencil matrix M by a separable transform
// (grid/spectral_transform.hpp: DFT on periodic axes, DCT-II / DST-II on even / odd axes; any
// number of ranks). One implicit diffusion substep (step()):
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
// otherwise; the caller then uses KSP. solve_negated() solves (-M) x = r (a Poisson or a shifted
// system given as its negation), with the null modes (lambda = 0) of x set to zero.
#pragma once

#include "grid/spectral_transform.hpp"
#include "operators/exact_solve.hpp"

#include <memory>
#include <petscmat.h>
#include <string>
#include <vector>

namespace morphogen {

// A deterministic, non-smooth test vector (every mode present), a function of the global cell:
// the probe of the exactness checks at setup.
void fill_spectral_probe(const Grid& grid, Vec x);

class SpectralSolver : public ExactSolve {
public:
  // Null (and *why set) when M is not diagonalised by the transform on this grid with these
  // axis kinds (default: the grid's boundaries, axis_kinds()).
  static std::unique_ptr<SpectralSolver> create(const Grid& grid, Mat M, std::string* why);
  static std::unique_ptr<SpectralSolver> create(const Grid& grid, Mat M, std::string* why,
                                                const std::array<AxisKind, 3>& kinds);
  ~SpectralSolver() override;
  SpectralSolver(const SpectralSolver&) = delete;
  SpectralSolver& operator=(const SpectralSolver&) = delete;

  // u <- (I - theta c M)^-1 (I + (1 - theta) c M) u, in place on a global Vec.
  void step(Vec u, double c, double theta) override;
  // x = (I - theta c M)^-1 r (the Dirichlet data's part of a substep).
  void solve_shifted(Vec r, Vec x, double c, double theta) override;
  std::string method() const override { return "spectral (FFT/DCT, exact)"; }
  // x = (-M)^+ r: the solution of -M x = r without null modes (r must be orthogonal to them).
  void solve_negated(Vec r, Vec x);

private:
  explicit SpectralSolver(std::unique_ptr<SpectralTransform> t);
  bool measure_symbol(const Grid& grid, Mat M, std::string* why);
  bool check_product(const Grid& grid, Mat M, std::string* why);
  std::unique_ptr<SpectralTransform> t_;
  std::vector<double> lambda_, gain_; // per spectral entry of this rank
  double gain_c_ = -1.0, gain_theta_ = -1.0, lmax_ = 0.0;
};

} // namespace morphogen
