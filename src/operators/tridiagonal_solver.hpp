// Exact implicit diffusion substeps (operators/exact_solve.hpp) by a transform of the fast axes
// and a tridiagonal solve along the slowest axis (y in 2-D, z in 3-D). For a constant-coefficient
// stencil without cross terms between the slowest and the other axes, T_rest (DFT on periodic,
// DCT-II / DST-II on zero-flux / Dirichlet fast axes; grid/spectral_transform.hpp, rest_only)
// turns M into one tridiagonal matrix per spectral column k along the slowest axis:
//
//   (T_rest M u)_j = a_k u_{j-1} + b_k u_j + g_k u_{j+1}   (first / last row: diagonal bF_k,
//   bL_k and no outer neighbour; periodic: the neighbours wrap),
//
// solved with I - theta c M by elimination, exactly (no iteration, no tolerance). The
// coefficients are measured, not assumed (M applied to three plane probes), and the model is
// checked at setup as in spectral_solver.hpp: the coefficients are real (no cross terms), every
// column is diagonally dominant, and M x equals the tridiagonal product for a probe x to 1e-10
// of the operator's scale. Against the full transform it saves the slowest axis' FFT and both
// transposes between the ranks.
//
// Parallel, layout A (each rank a block of m >= 2 whole planes): per column the interior rows of
// every block are eliminated (Thomas, no pivoting: I - theta c M is strictly diagonally
// dominant), leaving a reduced system for the first and last row of each block, 2P unknowns
// (cyclic when the slowest axis is periodic). Its right-hand sides are allgathered (2 planes per
// rank) and each rank forms its two unknowns from its two rows of the reduced inverse (LAPACK
// dgesv at setup, once per (c, theta)); the interior follows from the spikes
// p = A_I^-1 e_first, q = A_I^-1 e_last. The explicit half of Crank-Nicolson is the tridiagonal
// product with the neighbouring ranks' edge planes. A substep is three passes over the planes
// (transform, product and forward elimination going down; back substitution going up, the rows
// the spikes do not reach transformed back at once; the reduced system and the rest), with
// each plane in cache between its steps; the spikes decay geometrically and are kept only
// where they exceed 2^-64 (truncate_spikes). Waits are late: the edge planes travel while the
// down pass runs (the first row's product is formed last), and step_local_begin / _end let the
// reduced system's allgather of one species overlap the next species' passes (SplitIntegrator);
// step_local_group_begin runs several species' down passes in lockstep, plane by plane, with a
// caller's hook before each plane is first read (the split integrator's merged reaction).
// Back substitution writes the rows it emits at once to scratch rows (the spectrum's rows are
// then only read on the way up), and the down pass prefetches the state's planes three ahead.
// step_local keeps the spectrum in the local vector's own planes where each plane's stride holds a
// row (rows_in_state: no separate spectrum in memory; ghost cells under a row saved and restored).
// create() returns null and says why where it does not apply (at most kMaxRanks ranks, S >= 3
// planes); the caller then uses the full transform (spectral_solver.hpp) or KSP.
#pragma once

#include "grid/spectral_transform.hpp"
#include "operators/exact_solve.hpp"

#include <algorithm>
#include <functional>
#include <memory>
#include <petscmat.h>
#include <string>
#include <vector>

namespace morphogen {

class TridiagonalSolver : public ExactSolve {
public:
  static constexpr int kMaxRanks = 64;
  static std::unique_ptr<TridiagonalSolver> create(const Grid& grid, Mat M, std::string* why);
  ~TridiagonalSolver() override;
  TridiagonalSolver(const TridiagonalSolver&) = delete;
  TridiagonalSolver& operator=(const TridiagonalSolver&) = delete;

  void step(Vec u, double c, double theta) override;
  void solve_shifted(Vec r, Vec x, double c, double theta) override;
  bool steps_local() const override { return t_->direct(); }
  void step_local(Vec ulocal, double c, double theta) override;
  void step_local_begin(Vec ulocal, double c, double theta) override;
  void step_local_end(Vec ulocal) override;
  std::string method() const override;
  // Whether the last step_local kept its spectrum in the local vector's own planes (tests).
  bool last_step_in_place() const { return in_place_; }

  // One species' substep in a group of solvers on the same grid (step_local_group_begin).
  struct GroupMember {
    TridiagonalSolver* solver;
    Vec ulocal;
    double c, theta;
  };
  // step_local_begin for every member at once, their down passes in lockstep plane by plane:
  // before(g) is called once for every owned plane g of the slowest axis (global index) before
  // any member's transform reads it, so that the caller can update the plane's cells of every
  // species there while they are in cache (the split integrator's reaction). Then
  // step_local_end for each member.
  static void step_local_group_begin(const std::vector<GroupMember>& group,
                                     const std::function<void(PetscInt)>& before);

private:
  TridiagonalSolver(const Grid& grid, std::unique_ptr<SpectralTransform> t);
  void probe_plane(Mat M, PetscInt j0, std::vector<double>& out, double* imag);
  bool measure(Mat M, std::string* why);
  bool dominant(std::string* why) const;
  bool check_product(Mat M, std::string* why);
  void begin_edges();
  void end_edges();
  void exchange_edges();
  void multiply(double s0, double s1); // spectrum <- s0 y + s1 M y
  void factor(double c, double theta);
  void thomas_factors();
  void interior_factors();
  std::vector<double> reduced_rows() const;
  void reduced_inverse();
  void truncate_spikes();
  // Crank-Nicolson's explicit factor (1 - theta) c (0 for backward Euler: no product).
  static double explicit_part(double c, double theta) {
    return theta != 1.0 ? (1.0 - theta) * c : 0.0;
  }
  // One substep, x = (I - theta c M)^-1 (s0 + s1 M) r (s1 = 0: no product), in three passes
  // over the planes: down (transform, product, forward elimination), up (back substitution; the
  // rows the spikes do not reach go back to x at once), ends (reduced system, the other rows).
  void apply(Vec r, Vec x, double s0, double s1);
  void down(const PlaneView& in, double s0, double s1);
  void down_begin(const PlaneView& in, double s0, double s1);
  void down_plane(const PlaneView& in, PetscInt j);
  void down_end();
  void map_local(Vec ulocal, double c, double theta);
  void up(const PlaneView& out);
  void ends_begin(); // the reduced system's right-hand sides, their allgather posted
  void ends(const PlaneView& out);
  bool spiked(PetscInt i) const { return i < kp_ || i >= m_ - 2 - kq_; } // interior row i
  void emit(PetscInt j, const PlaneView& out) { t_->plane_backward(row(j), out, j); }
  double* row(PetscInt j) { return rows_ + j * row_stride_; }
  void rows_in_spectrum() {
    rows_ = t_->spectrum();
    row_stride_ = n_;
  }
  bool rows_in_state(Vec ulocal); // step_local: spectral row j in place of owned plane j
  void restore_ghosts();
  const double* diagonal(PetscInt j) const; // M's diagonal of my row j

  const Grid& grid_;
  std::unique_ptr<SpectralTransform> t_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1, w_ = 1;
  bool periodic_ = false;
  PetscInt S_ = 0, a0_ = 0, m_ = 0;
  int n_ = 0;                               // lanes per plane (spectral columns x width)
  std::vector<double> a_, b_, g_, bF_, bL_; // M's coefficients per lane
  std::vector<double> lo_, hi_;             // the neighbours' edge planes (zero outside)
  double fc_ = -1.0, ftheta_ = -1.0;        // (c, theta) of the factors below
  // I - theta c M: off-diagonals, interior diagonal, the diagonals of my first and last row
  std::vector<double> ia_, ig_, ib_, ifirst_, ilast_;
  std::vector<double> inv_, gp_; // [interior row][lane]: the first nfac_ rows
  PetscInt nfac_ = 0;
  // The spikes' rows that matter: p_ the first kp_ interior rows, q_ the last kq_ (beyond them
  // |a p|, |g q| < 2^-64 in every lane; see truncate_spikes).
  std::vector<double> p_, q_;
  PetscInt kp_ = 0, kq_ = 0;
  std::vector<double> pa_, zero_, F_, E_; // one row each (pa_: down()'s carried a x_{j-1})
  std::vector<double> xs_;                // up()'s two scratch rows
  std::vector<double> raw1_; // down(): plane 1 before its product (row 0's product needs it)
  bool product_ = false;     // down(): with the explicit product, its scales (1/norm folded in)
  double s0_ = 0.0, s1_ = 0.0;
  MPI_Request edge_req_[4] = {MPI_REQUEST_NULL, MPI_REQUEST_NULL, MPI_REQUEST_NULL,
                              MPI_REQUEST_NULL};
  size_t scratch_stride() const { return (static_cast<size_t>(n_) + 7) / 8 * 8; }
  double* scratch(int k);
  const double* inv_row(PetscInt i) const {
    return inv_.data() + static_cast<size_t>(std::min(i, nfac_ - 1)) * static_cast<size_t>(n_);
  }
  const double* gp_row(PetscInt i) const {
    return gp_.data() + static_cast<size_t>(std::min(i, nfac_ - 1)) * static_cast<size_t>(n_);
  }
  std::vector<double> rinv_; // [2][2P][lane]: my rows of the reduced inverse
  std::vector<double> gmine_, gall_;
  MPI_Request gather_req_ = MPI_REQUEST_NULL;
  // Spectral row j: rows_ + j row_stride_ (the transform's spectrum, or the owned planes of a
  // local vector, each at least n_ doubles long, in step_local: no separate spectrum in memory).
  double* rows_ = nullptr;
  std::ptrdiff_t row_stride_ = 0;
  std::vector<std::ptrdiff_t> span_ghosts_; // in place: offsets in a row that are ghost cells
  std::vector<double> ghost_save_;          // and their values, plane by plane
  bool in_place_ = false;
  PlaneView local_;               // step_local_begin's view of the local vector
  double* local_array_ = nullptr; // and its array (restored by step_local_end)
};

} // namespace morphogen
