// Distributed separable transform of a DMDA field for the spectral diffusion solve:
//
//   T = T_slow (x) T_rest,  per axis: periodic -> DFT, even (zero flux, the cell-centred mirror
//   ghost u_-1 = u_0) -> DCT-II, odd (zero value on the face, ghost u_-1 = -u_0) -> DST-II,
//
// with dims slowest first (2-D: y | x; 3-D: z | y, x). All axes periodic: complex DFT (r2c on
// the rest, complex DFT on the slow axis), so symmetric stencils with cross terms stay diagonal.
// Otherwise real r2r kinds: R2HC on periodic axes, REDFT10 on even and RODFT10 on odd axes
// (backward HC2R, REDFT01, RODFT01). FFTW is unnormalised: backward(forward(u)) = norm() u.
// The even and odd kinds are computed by TrigTransform (grid/trig_transform.hpp: one real or
// paired complex FFT each, not FFTW's scalar r2r codelets) on the rest axes when none of them is
// periodic, and on the slow axis when it is not.
//
// Parallel layout (slabs): layout A gives each rank a contiguous range of slow-axis planes,
// where T_rest runs; layout B gives each rank a range of spectral columns (all slow-axis
// entries of them), where T_slow runs and where the spectrum lives. A -> B and back are one
// MPI_Alltoallv each (the block for rank q packed from this rank's planes; the block from rank
// p lands as p's rows of B with no unpacking; this rank's own block is copied directly). When
// the DMDA is split along the slow axis only (1 x 1 x P or 1 x P), layout A takes its ranges
// and T_rest reads and writes the DMDA vector itself; otherwise a PetscSF scatter moves the
// field between the DMDA and layout A. Useful up to min(slow cells, spectral columns) ranks.
// rest_only: T_rest alone (no slow-axis transform, no transposes): the spectrum is layout A,
// planes() planes from first_plane() of columns() entries each, rest axes' normalisation; the
// DFT is complex (r2c) when every rest axis is periodic (operators/tridiagonal_solver.hpp).
// Plans: grid/fft_planning.hpp (FFTW_MEASURE by default, kept in a wisdom file so that later
// runs re-create the same plans and the same arithmetic).
#pragma once

#include "grid/grid.hpp"

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

namespace morphogen {

enum class AxisKind { Periodic, Even, Odd };

// Where the planes of layout A lie in an array: row r (of `rows` rows of `len` reals) of plane j
// (from first_plane()) at base + j * plane + r * row.
struct PlaneView {
  double* base = nullptr;
  std::ptrdiff_t plane = 0, row = 0;
  PetscInt rows = 1, len = 0;
};

// The kinds of the grid's boundaries: periodic, Neumann -> even, Dirichlet -> odd.
std::array<AxisKind, 3> axis_kinds(const Grid& grid);

class SpectralTransform {
public:
  SpectralTransform(const Grid& grid, const std::array<AxisKind, 3>& kinds, bool rest_only = false);
  ~SpectralTransform();
  SpectralTransform(const SpectralTransform&) = delete;
  SpectralTransform& operator=(const SpectralTransform&) = delete;

  void forward(Vec u);  // spectrum() = T u
  void backward(Vec u); // u = T^-1 spectrum() * norm() (destroys the spectrum)
  double* spectrum() { return specB_; }
  // This rank's spectral entries, each width() doubles (2: complex, 1: real).
  size_t entries() const {
    return rest_only_ ? static_cast<size_t>(a1_ - a0_) * static_cast<size_t>(ncolsS_)
                      : static_cast<size_t>(S_) * static_cast<size_t>(nb_);
  }
  // Layout A (the spectrum of a rest_only transform): this rank's planes, spectral columns.
  PetscInt first_plane() const { return a0_; }
  PetscInt planes() const { return a1_ - a0_; }
  PetscInt columns() const { return ncolsS_; }
  PetscInt slow_cells() const { return S_; }
  int width() const { return w_; }
  double norm() const { return norm_; }

  // Plane by plane (rest_only, for passes fused with the slow-axis solve): layout A's reals of
  // the global vector u (u's own array when direct, else a scattered copy: fetch fills it from
  // u); reals_done returns the array (store: the copy back into u). direct(): layout A is the
  // DMDA's own decomposition (so a ghosted local vector's owned planes are layout A too).
  PlaneView reals(Vec u, bool fetch);
  void reals_done(Vec u, const PlaneView& v, bool store);
  bool direct() const { return direct_; }
  // spec = T_rest (plane j); spec and plane j may overlap (spec then replaces the plane).
  void plane_forward(const PlaneView& v, PetscInt j, double* spec);
  void plane_backward(double* spec, const PlaneView& v, PetscInt j); // spec destroyed

private:
  void plan(const Grid& grid, const std::array<AxisKind, 3>& kinds);
  void make_scatter(const Grid& grid);
  void slab_ranges(const Grid& grid);
  void transpose_counts();
  void copy_blocks(bool to_b);
  void to_columns();   // layout A -> B
  void from_columns(); // layout B -> A
  void rest_forward(Vec u);
  void rest_backward(Vec u);
  void trig_plane_forward(const double* p, std::ptrdiff_t row, PetscInt rows, double* spec);
  void trig_plane_backward(double* spec, double* p, std::ptrdiff_t row, PetscInt rows);
  PetscInt S_ = 1, ncols_ = 1, ncolsS_ = 1;    // slow-axis cells, rest cells, rest spectral columns
  PetscInt nx_ = 1;                            // cells along x (a row of a plane)
  PetscInt a0_ = 0, a1_ = 0, b0_ = 0, nb_ = 0; // my slow planes [a0, a1), columns [b0, b0 + nb)
  int w_ = 1, size_ = 1, rank_ = 0;
  bool rest_only_ = false;
  bool direct_ = true; // layout A is this rank's part of the DMDA vector
  MPI_Comm comm_ = MPI_COMM_NULL;
  std::vector<PetscInt> aparts_, bparts_; // [size + 1]: first plane / column of each rank
  std::vector<int> scount_, sdispl_, rcount_, rdispl_;
  std::vector<double> xbuf_; // packed blocks of the transposes
  double norm_ = 1.0;
  double *realA_ = nullptr, *specA_ = nullptr, *specB_ = nullptr;
  double *planeR_ = nullptr, *planeS_ = nullptr; // one aligned plane each (rest_only)
  struct Plans;
  std::unique_ptr<Plans> plans_;
  VecH vA_;
  SFH toA_; // DMDA -> layout A (reals), when not direct_
};

} // namespace morphogen
