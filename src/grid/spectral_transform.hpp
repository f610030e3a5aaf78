// Distributed separable transform of a DMDA field for the spectral diffusion solve:
//
//   T = T_slow (x) T_rest,  per axis: periodic -> DFT, even (zero flux, the cell-centred mirror
//   ghost u_-1 = u_0) -> DCT-II, odd (zero value on the face, ghost u_-1 = -u_0) -> DST-II,
//
// with dims slowest first (2-D: y | x; 3-D: z | y, x). All axes periodic: complex DFT (r2c on
// the rest, complex DFT on the slow axis), so symmetric stencils with cross terms stay diagonal.
// Otherwise real r2r kinds: R2HC on periodic axes, REDFT10 on even and RODFT10 on odd axes
// (backward HC2R, REDFT01, RODFT01). FFTW is unnormalised: backward(forward(u)) = norm() u.
//
// Parallel layout (slabs, two transposes by PetscSF scatters): layout A gives each rank a
// contiguous range of slow-axis planes, where T_rest runs; layout B gives each rank a range of
// spectral columns (all slow-axis entries of them), where T_slow runs and where the spectrum
// lives. Useful up to min(slow cells, spectral columns) ranks; on one rank nothing is scattered.
// Plans: grid/fft_planning.hpp (FFTW_MEASURE by default, kept in a wisdom file so that later
// runs re-create the same plans and the same arithmetic).
#pragma once

#include "grid/grid.hpp"

#include <array>
#include <memory>
#include <vector>

namespace morphogen {

enum class AxisKind { Periodic, Even, Odd };

// The kinds of the grid's boundaries: periodic, Neumann -> even, Dirichlet -> odd.
std::array<AxisKind, 3> axis_kinds(const Grid& grid);

class SpectralTransform {
public:
  SpectralTransform(const Grid& grid, const std::array<AxisKind, 3>& kinds);
  ~SpectralTransform();
  SpectralTransform(const SpectralTransform&) = delete;
  SpectralTransform& operator=(const SpectralTransform&) = delete;

  void forward(Vec u);  // spectrum() = T u
  void backward(Vec u); // u = T^-1 spectrum() * norm() (destroys the spectrum)
  double* spectrum() { return specB_; }
  // This rank's spectral entries, each width() doubles (2: complex, 1: real).
  size_t entries() const { return static_cast<size_t>(S_) * static_cast<size_t>(nb_); }
  int width() const { return w_; }
  double norm() const { return norm_; }

private:
  void plan(const Grid& grid, const std::array<AxisKind, 3>& kinds);
  void make_scatters(const Grid& grid);
  PetscInt S_ = 1, ncols_ = 1, ncolsS_ = 1;    // slow-axis cells, rest cells, rest spectral columns
  PetscInt a0_ = 0, a1_ = 0, b0_ = 0, nb_ = 0; // my slow planes [a0, a1), columns [b0, b0 + nb)
  int w_ = 1, size_ = 1;
  double norm_ = 1.0;
  double *realA_ = nullptr, *specA_ = nullptr, *specB_ = nullptr;
  struct Plans;
  std::unique_ptr<Plans> plans_;
  VecH vA_, vSA_, vSB_;
  SFH toA_, toB_; // DMDA -> layout A (reals), layout A -> B (spectral entries)
};

} // namespace morphogen
