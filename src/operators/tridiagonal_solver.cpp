#include "operators/tridiagonal_solver.hpp"

#include "core/petsc_handle.hpp"
#include "core/prefetch.hpp"
#include "operators/spectral_solver.hpp"
#include "operators/tridiagonal_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

// LAPACK (Fortran): solve A X = B by LU with partial pivoting.
extern "C" void dgesv_(const int* n, const int* nrhs, double* a, const int* lda, int* ipiv,
                       double* b, const int* ldb, int* info);

namespace morphogen {

TridiagonalSolver::TridiagonalSolver(const Grid& grid, std::unique_ptr<SpectralTransform> t)
    : grid_(grid), t_(std::move(t)), comm_(grid.comm()) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  w_ = t_->width();
  periodic_ = axis_kinds(grid)[grid.dim() - 1] == AxisKind::Periodic;
  S_ = t_->slow_cells();
  a0_ = t_->first_plane();
  m_ = t_->planes();
  n_ = static_cast<int>(t_->columns()) * w_;
  lo_.assign(static_cast<size_t>(n_), 0.0);
  hi_ = lo_;
  xs_.assign(2 * scratch_stride() + 8, 0.0);
  rows_in_spectrum();
}

// Scratch row k (0 or 1) of up(), 64-byte aligned (FFTW's inverse plans then read it directly).
double* TridiagonalSolver::scratch(int k) {
  const auto addr = reinterpret_cast<std::uintptr_t>(xs_.data());
  double* base = xs_.data() + (64 - addr % 64) % 64 / sizeof(double);
  return base + static_cast<size_t>(k) * scratch_stride();
}

TridiagonalSolver::~TridiagonalSolver() = default;

std::unique_ptr<TridiagonalSolver> TridiagonalSolver::create(const Grid& grid, Mat M,
                                                             std::string* why) {
  int size = 1;
  MPI_Comm_size(grid.comm(), &size);
  const PetscInt S = grid.spec().n[grid.dim() - 1];
  if (size > kMaxRanks || S < 3) {
    *why = size > kMaxRanks ? "more than " + std::to_string(kMaxRanks) + " ranks"
                            : "fewer than 3 cells along the slowest axis";
    return nullptr;
  }
  auto t = std::make_unique<SpectralTransform>(grid, axis_kinds(grid), true);
  int planes = static_cast<int>(t->planes());
  MPI_Allreduce(MPI_IN_PLACE, &planes, 1, MPI_INT, MPI_MIN, grid.comm());
  if (planes < 2) {
    *why = "a rank holds fewer than 2 planes of the slowest axis";
    return nullptr;
  }
  std::unique_ptr<TridiagonalSolver> ts(new TridiagonalSolver(grid, std::move(t)));
  if (!ts->measure(M, why) || !ts->dominant(why) || !ts->check_product(M, why)) return nullptr;
  return ts;
}

std::string TridiagonalSolver::method() const {
  return std::string("spectral (FFT/DCT across, tridiagonal along ") +
         (grid_.dim() == 3 ? "z" : "y") + ", exact)";
}

// out[r][lane] = (T_rest M T_rest^-1 e_j0)(row j0 + r - 1) / norm for r = 0, 1, 2 (rows off a
// non-periodic axis stay 0), summed over the ranks; *imag: the largest imaginary part.
void TridiagonalSolver::probe_plane(Mat M, PetscInt j0, std::vector<double>& out, double* imag) {
  SpectralTransform& t = *t_;
  double* sp = t.spectrum();
  std::fill(sp, sp + static_cast<size_t>(m_) * static_cast<size_t>(n_), 0.0);
  if (j0 >= a0_ && j0 < a0_ + m_)
    for (int l = 0; l < n_; l += w_)
      row(j0 - a0_)[l] = 1.0;
  VecH v = grid_.create_global(), y = grid_.create_global();
  t.backward(v);
  MG_PETSC(MatMult(M, v, y));
  t.forward(y);
  out.assign(3 * static_cast<size_t>(n_), 0.0);
  double im = 0.0;
  for (int r = 0; r < 3; ++r) {
    PetscInt j = j0 + r - 1;
    if (periodic_) j = (j + S_) % S_;
    if (j < a0_ || j >= a0_ + m_) continue;
    const double* y_j = row(j - a0_);
    for (int l = 0; l < n_; ++l) {
      const int k = l - l % w_; // the column's real part
      out[static_cast<size_t>(r * n_ + l)] = y_j[k] / t.norm();
      if (w_ == 2) im = std::max(im, std::fabs(y_j[k + 1]) / t.norm());
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, out.data(), 3 * n_, MPI_DOUBLE, MPI_SUM, comm_);
  MPI_Allreduce(MPI_IN_PLACE, &im, 1, MPI_DOUBLE, MPI_MAX, comm_);
  *imag = std::max(*imag, im);
}

// a, b, g from a probe of an interior plane, bF and bL from the first and the last plane.
bool TridiagonalSolver::measure(Mat M, std::string* why) {
  std::vector<double> r;
  double imag = 0.0;
  const size_t n = static_cast<size_t>(n_);
  probe_plane(M, S_ / 2, r, &imag);
  g_.assign(r.begin(), r.begin() + n);
  b_.assign(r.begin() + n, r.begin() + 2 * n);
  a_.assign(r.begin() + 2 * n, r.end());
  probe_plane(M, 0, r, &imag);
  bF_.assign(r.begin() + n, r.begin() + 2 * n);
  probe_plane(M, S_ - 1, r, &imag);
  bL_.assign(r.begin() + n, r.begin() + 2 * n);
  double scale = 0.0;
  for (size_t l = 0; l < n; ++l)
    scale = std::max(scale, std::fabs(a_[l]) + std::fabs(b_[l]) + std::fabs(g_[l]));
  if (!(scale > 0.0) || !(imag <= 1e-12 * scale)) {
    *why = "the operator couples the slowest axis to the others (cross terms)";
    return false;
  }
  return true;
}

// Every column weakly diagonally dominant with a non-positive diagonal (to 1e-12 of the scale),
// so that I - theta c M is strictly dominant for every theta c >= 0.
bool TridiagonalSolver::dominant(std::string* why) const {
  int ok = 1;
  for (size_t l = 0; l < static_cast<size_t>(n_); ++l) {
    const double aa = std::fabs(a_[l]), gg = std::fabs(g_[l]);
    const double tol = 1e-12 * (aa + gg + std::fabs(b_[l]));
    ok &= -b_[l] >= aa + gg - tol && -bF_[l] >= gg + (periodic_ ? aa : 0.0) - tol &&
                  -bL_[l] >= aa + (periodic_ ? gg : 0.0) - tol
              ? 1
              : 0;
  }
  MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, comm_);
  if (!ok) *why = "the operator is not diagonally dominant along the slowest axis";
  return ok != 0;
}

// M x against T_rest^-1 (tridiagonal product of T_rest x) for a probe x.
bool TridiagonalSolver::check_product(Mat M, std::string* why) {
  VecH x = grid_.create_global(), y = grid_.create_global(), z = grid_.create_global();
  fill_spectral_probe(grid_, x);
  MG_PETSC(MatMult(M, x, y));
  t_->forward(x);
  multiply(0.0, 1.0 / t_->norm());
  t_->backward(z);
  double scale = 0.0;
  for (size_t l = 0; l < static_cast<size_t>(n_); ++l)
    scale = std::max(scale, std::fabs(a_[l]) + std::fabs(b_[l]) + std::fabs(g_[l]));
  MPI_Allreduce(MPI_IN_PLACE, &scale, 1, MPI_DOUBLE, MPI_MAX, comm_);
  PetscReal dnorm;
  MG_PETSC(VecAXPY(z, -1.0, y));
  MG_PETSC(VecNorm(z, NORM_INFINITY, &dnorm));
  if (!(dnorm <= 1e-10 * scale * 1.5)) { // |probe| <= 1.1
    *why = "the operator is not a constant-coefficient stencil, tridiagonal along the slowest "
           "axis (M x differs from the product by " +
           std::to_string(dnorm) + ")";
    return false;
  }
  return true;
}

// lo_ = plane a0 - 1, hi_ = plane a0 + m (wrapped when periodic; zero off the axis): posted by
// begin_edges (rows 0 and m - 1 are sent from and must not change until end_edges).
void TridiagonalSolver::begin_edges() {
  const int left = rank_ > 0 ? rank_ - 1 : periodic_ ? size_ - 1 : MPI_PROC_NULL;
  const int right = rank_ < size_ - 1 ? rank_ + 1 : periodic_ ? 0 : MPI_PROC_NULL;
  std::fill(lo_.begin(), lo_.end(), 0.0);
  std::fill(hi_.begin(), hi_.end(), 0.0);
  MPI_Irecv(lo_.data(), n_, MPI_DOUBLE, left, 0, comm_, &edge_req_[0]);
  MPI_Irecv(hi_.data(), n_, MPI_DOUBLE, right, 1, comm_, &edge_req_[1]);
  MPI_Isend(row(m_ - 1), n_, MPI_DOUBLE, right, 0, comm_, &edge_req_[2]);
  MPI_Isend(row(0), n_, MPI_DOUBLE, left, 1, comm_, &edge_req_[3]);
}

void TridiagonalSolver::end_edges() {
  MPI_Waitall(4, edge_req_, MPI_STATUSES_IGNORE);
}

void TridiagonalSolver::exchange_edges() {
  begin_edges();
  end_edges();
}

const double* TridiagonalSolver::diagonal(PetscInt j) const {
  const PetscInt gj = a0_ + j;
  return gj == 0 ? bF_.data() : gj == S_ - 1 ? bL_.data() : b_.data();
}

void TridiagonalSolver::multiply(double s0, double s1) {
  exchange_edges();
  std::vector<double> pa(static_cast<size_t>(n_));
  tri_times_row(n_, a_.data(), lo_.data(), pa.data());
  for (PetscInt j = 0; j < m_; ++j)
    tri_multiply_row_carry(n_, s0, s1, a_.data(), diagonal(j), g_.data(), pa.data(),
                           j + 1 < m_ ? row(j + 1) : hi_.data(), row(j));
}

void TridiagonalSolver::factor(double c, double theta) {
  if (c == fc_ && theta == ftheta_) return;
  const size_t n = static_cast<size_t>(n_);
  ia_.resize(n);
  ig_.resize(n);
  ib_.resize(n);
  ifirst_.resize(n);
  ilast_.resize(n);
  const double* bf = diagonal(0);
  const double* bl = diagonal(m_ - 1);
  for (size_t l = 0; l < n; ++l) {
    ia_[l] = -theta * c * a_[l];
    ig_[l] = -theta * c * g_[l];
    ib_[l] = 1.0 - theta * c * b_[l];
    ifirst_[l] = 1.0 - theta * c * bf[l];
    ilast_[l] = 1.0 - theta * c * bl[l];
  }
  interior_factors();
  reduced_inverse();
  truncate_spikes();
  fc_ = c;
  ftheta_ = theta;
}

// Thomas factors of the interior block (rows 1 .. m-2, diagonal ib): inv_i = 1 / (ib - ia
// gp_{i-1}), gp_i = ig inv_i. The recurrence reaches its fixed point in floating point within a few
// hundred rows (it contracts); from the first row equal to its predecessor in every lane on,
// all rows are that row, so only the rows before it are kept (nfac_; inv_row / gp_row).
void TridiagonalSolver::thomas_factors() {
  const size_t n = static_cast<size_t>(n_), ni = static_cast<size_t>(m_ - 2);
  inv_.assign(ni * n, 0.0);
  gp_.assign(ni * n, 0.0);
  nfac_ = static_cast<PetscInt>(ni);
  for (size_t i = 0; i < ni; ++i) {
    for (size_t l = 0; l < n; ++l) {
      const double den = ib_[l] - (i > 0 ? ia_[l] * gp_[(i - 1) * n + l] : 0.0);
      inv_[i * n + l] = 1.0 / den;
      gp_[i * n + l] = ig_[l] * inv_[i * n + l];
    }
    if (i > 0 && std::equal(&inv_[i * n], &inv_[i * n] + n, &inv_[(i - 1) * n]) &&
        std::equal(&gp_[i * n], &gp_[i * n] + n, &gp_[(i - 1) * n])) {
      nfac_ = static_cast<PetscInt>(i);
      break;
    }
  }
  inv_.resize(static_cast<size_t>(nfac_) * n);
  gp_.resize(static_cast<size_t>(nfac_) * n);
  inv_.shrink_to_fit();
  gp_.shrink_to_fit();
}

// The Thomas factors and the interior's spikes p = A_I^-1 e_first, q = A_I^-1 e_last. Spike
// entries below 1e-290 (they decay geometrically away from their row) are set to 0 so that no
// subnormal number reaches the solves.
void TridiagonalSolver::interior_factors() {
  const size_t n = static_cast<size_t>(n_), ni = static_cast<size_t>(m_ - 2);
  thomas_factors();
  p_.assign(ni * n, 0.0);
  q_.assign(ni * n, 0.0);
  if (ni == 0) return;
  auto tiny = [](double& v) {
    if (std::fabs(v) < 1e-290) v = 0.0;
  };
  for (size_t i = 0; i < ni; ++i) { // forward sweeps of e_first and e_last
    const double* inv = inv_row(static_cast<PetscInt>(i));
    for (size_t l = 0; l < n; ++l) {
      p_[i * n + l] = i == 0 ? inv[l] : -ia_[l] * p_[(i - 1) * n + l] * inv[l];
      q_[i * n + l] = i + 1 == ni ? inv[l] : 0.0;
    }
  }
  for (size_t i = ni - 1; i-- > 0;) { // back substitution
    const double* gp = gp_row(static_cast<PetscInt>(i));
    for (size_t l = 0; l < n; ++l) {
      p_[i * n + l] -= gp[l] * p_[(i + 1) * n + l];
      q_[i * n + l] -= gp[l] * q_[(i + 1) * n + l];
    }
  }
  std::for_each(p_.begin(), p_.end(), tiny);
  std::for_each(q_.begin(), q_.end(), tiny);
}

// This rank's two rows of the reduced matrix, per lane: the coupling of F to the previous
// block's E, S_FF, S_FE, S_EF, S_EE, the coupling of E to the next block's F.
std::vector<double> TridiagonalSolver::reduced_rows() const {
  const size_t n = static_cast<size_t>(n_), ni = static_cast<size_t>(m_ - 2);
  std::vector<double> r(6 * n);
  for (size_t l = 0; l < n; ++l) {
    const double a = ia_[l], g = ig_[l];
    const bool inner = ni > 0;
    r[l] = rank_ > 0 || periodic_ ? a : 0.0;
    r[n + l] = inner ? ifirst_[l] - g * a * p_[l] : ifirst_[l];
    r[2 * n + l] = inner ? -g * g * q_[l] : g;
    r[3 * n + l] = inner ? -a * a * p_[(ni - 1) * n + l] : a;
    r[4 * n + l] = inner ? ilast_[l] - a * g * q_[(ni - 1) * n + l] : ilast_[l];
    r[5 * n + l] = rank_ < size_ - 1 || periodic_ ? g : 0.0;
  }
  return r;
}

// The reduced system (unknowns F_0, E_0, F_1, ..., E_{P-1}: the first and last row of every
// block) from every rank's rows; per lane, my two rows of its inverse: S^T X = (e_2r, e_2r+1).
void TridiagonalSolver::reduced_inverse() {
  const size_t n = static_cast<size_t>(n_);
  const int K = 2 * size_;
  const std::vector<double> mine = reduced_rows();
  std::vector<double> all(mine.size() * static_cast<size_t>(size_));
  MPI_Allgather(mine.data(), 6 * n_, MPI_DOUBLE, all.data(), 6 * n_, MPI_DOUBLE, comm_);
  rinv_.assign(2 * static_cast<size_t>(K) * n, 0.0);
  std::vector<double> A(static_cast<size_t>(K * K)), X(2 * static_cast<size_t>(K));
  std::vector<int> piv(static_cast<size_t>(K));
  for (size_t l = 0; l < n; ++l) {
    std::fill(A.begin(), A.end(), 0.0);
    auto add = [&](int r, int c, double v) { A[static_cast<size_t>(c + r * K)] += v; }; // S^T
    for (int q = 0; q < size_; ++q) {
      const double* e = all.data() + 6 * n * static_cast<size_t>(q) + l;
      const int F = 2 * q, E = 2 * q + 1;
      add(F, (F - 1 + K) % K, e[0]);
      add(F, F, e[n]);
      add(F, E, e[2 * n]);
      add(E, F, e[3 * n]);
      add(E, E, e[4 * n]);
      add(E, (E + 1) % K, e[5 * n]);
    }
    std::fill(X.begin(), X.end(), 0.0);
    X[static_cast<size_t>(2 * rank_)] = 1.0;
    X[static_cast<size_t>(K + 2 * rank_ + 1)] = 1.0;
    const int two = 2;
    int info = 0;
    dgesv_(&K, &two, A.data(), &K, piv.data(), X.data(), &K, &info);
    if (info != 0) throw std::runtime_error("tridiagonal solve: singular reduced system");
    for (int k = 0; k < 2 * K; ++k)
      rinv_[static_cast<size_t>(k) * n + l] = X[static_cast<size_t>(k)];
  }
}

// The spikes decay geometrically away from their row. The correction a F p_i of interior row i
// is below 2^-64 |F| (F: a value of the same column's solution) once |a p_i| < 2^-64 in every
// lane: far below the rounding of the transforms. Only the rows before that are kept (at least
// one: the reduced system and its right-hand side use the first and the last interior row).
void TridiagonalSolver::truncate_spikes() {
  const size_t n = static_cast<size_t>(n_);
  const PetscInt ni = m_ - 2;
  const double tol = std::ldexp(1.0, -64);
  auto reaches = [&](const std::vector<double>& v, const std::vector<double>& c, PetscInt i) {
    for (size_t l = 0; l < n; ++l)
      if (std::fabs(c[l] * v[static_cast<size_t>(i) * n + l]) >= tol) return true;
    return false;
  };
  kp_ = std::min<PetscInt>(ni, 1);
  for (PetscInt i = ni - 1; i >= 1; --i)
    if (reaches(p_, ia_, i)) {
      kp_ = i + 1;
      break;
    }
  kq_ = std::min<PetscInt>(ni, 1);
  for (PetscInt i = 0; i < ni - 1; ++i)
    if (reaches(q_, ig_, i)) {
      kq_ = ni - i;
      break;
    }
  p_.resize(static_cast<size_t>(kp_) * n);
  q_.erase(q_.begin(), q_.begin() + static_cast<std::ptrdiff_t>((ni - kq_) * n_));
  p_.shrink_to_fit();
  q_.shrink_to_fit();
  zero_.assign(n, 0.0);
}

// x = (I - theta c M)^-1 (s0 + s1 M) r.
void TridiagonalSolver::apply(Vec r, Vec x, double s0, double s1) {
  rows_in_spectrum();
  PlaneView v = t_->reals(r, true);
  down(v, s0, s1);
  if (x != r) {
    t_->reals_done(r, v, false);
    v = t_->reals(x, false);
  }
  up(v);
  ends_begin();
  ends(v);
  t_->reals_done(x, v, true);
}

// Plane by plane: the transform, the right-hand side (s0 f + s1 M f) / norm (the neighbours'
// edge planes exchanged first; the transform's 1/norm folded in), the forward elimination of
// the interior rows. down_plane(j) transforms plane j + 1 (with the product; else plane j), and
// down_begin planes 0 and m - 1.
void TridiagonalSolver::down(const PlaneView& in, double s0, double s1) {
  down_begin(in, s0, s1);
  for (PetscInt j = 0; j < m_; ++j)
    down_plane(in, j);
  down_end();
}

void TridiagonalSolver::down_begin(const PlaneView& in, double s0, double s1) {
  product_ = s1 != 0.0;
  s0_ = s0 / t_->norm();
  s1_ = s1 / t_->norm();
  if (!product_) return;
  const size_t n = static_cast<size_t>(n_);
  t_->plane_forward(in, 0, row(0));
  t_->plane_forward(in, m_ - 1, row(m_ - 1));
  begin_edges(); // arrive while the planes between are transformed (hi_ used at m - 1, lo_ last)
  pa_.resize(n);
  raw1_.resize(n);
}

void TridiagonalSolver::down_plane(const PlaneView& in, PetscInt j) {
  double* y = row(j);
  if (product_) {
    if (j + 3 < m_ - 1)
      for (PetscInt r = 0; r < in.rows; ++r)
        prefetch_doubles(in.base + (j + 3) * in.plane + r * in.row, in.len);
    if (j + 1 < m_ - 1) t_->plane_forward(in, j + 1, row(j + 1));
    if (j == m_ - 1) end_edges();
    if (j == 0) { // row 0's product waits for lo_ (down_end); row 1 as it is now
      tri_times_row(n_, a_.data(), y, pa_.data());
      std::copy(row(1), row(1) + n_, raw1_.begin());
    } else
      tri_multiply_row_carry(n_, s0_, s1_, a_.data(), diagonal(j), g_.data(), pa_.data(),
                             j + 1 < m_ ? row(j + 1) : hi_.data(), y);
  } else {
    t_->plane_forward(in, j, y);
    tri_scale_row(n_, s0_, y);
  }
  if (j >= 1 && j <= m_ - 2)
    tri_forward_row(n_, ia_.data(), inv_row(j - 1), j > 1 ? row(j - 1) : nullptr, y);
}

void TridiagonalSolver::down_end() {
  if (product_) { // row 0 is no interior row: the elimination did not use it
    tri_times_row(n_, a_.data(), lo_.data(), pa_.data());
    tri_multiply_row_carry(n_, s0_, s1_, a_.data(), diagonal(0), g_.data(), pa_.data(),
                           raw1_.data(), row(0));
  }
}

// Back substitution of the interior; an interior row the spikes do not reach is final and goes
// back to the reals once the row above has used it. Such rows are formed in two scratch rows
// (alternating), not in the spectrum: its rows are then only read here, so that their cache
// lines are not written back to memory (the spiked rows stay in the spectrum for ends()).
void TridiagonalSolver::up(const PlaneView& out) {
  const PetscInt ni = m_ - 2;
  if (ni < 1) return;
  const double* next = row(ni);
  for (PetscInt i = ni - 2; i >= 0; --i) {
    if (i >= 2) prefetch_doubles(row(i - 1), n_);
    double* x = spiked(i) ? row(i + 1) : scratch(static_cast<int>(i & 1));
    tri_backward_row(n_, gp_row(i), next, row(i + 1), x);
    if (!spiked(i + 1)) t_->plane_backward(const_cast<double*>(next), out, i + 2);
    next = x;
  }
}

// The reduced system's right-hand sides of this block (first and last interior rows after up),
// allgathered without waiting (ends() waits).
void TridiagonalSolver::ends_begin() {
  const size_t n = static_cast<size_t>(n_);
  const PetscInt ni = m_ - 2;
  gmine_.resize(2 * n);
  const double *f0 = row(0), *f1 = row(1), *fe = row(m_ - 1), *fe1 = row(m_ - 2);
  for (size_t l = 0; l < n; ++l) {
    gmine_[l] = ni > 0 ? f0[l] - ig_[l] * f1[l] : f0[l];
    gmine_[n + l] = ni > 0 ? fe[l] - ia_[l] * fe1[l] : fe[l];
  }
  gall_.resize(static_cast<size_t>(2 * size_) * n);
  MPI_Iallgather(gmine_.data(), 2 * n_, MPI_DOUBLE, gall_.data(), 2 * n_, MPI_DOUBLE, comm_,
                 &gather_req_);
}

// The block's ends F, E from the reduced system (after ends_begin), the spiked interior rows
// corrected, and all of them back to the reals.
void TridiagonalSolver::ends(const PlaneView& out) {
  const size_t n = static_cast<size_t>(n_);
  const PetscInt ni = m_ - 2;
  const int K = 2 * size_;
  MPI_Wait(&gather_req_, MPI_STATUS_IGNORE);
  F_.assign(n, 0.0);
  E_.assign(n, 0.0);
  for (int k = 0; k < K; ++k)
    tri_reduced_row(n_, &rinv_[static_cast<size_t>(k) * n], &rinv_[static_cast<size_t>(K + k) * n],
                    &gall_[static_cast<size_t>(k) * n], F_.data(), E_.data());
  for (PetscInt i = 0; i < ni; ++i) {
    if (!spiked(i)) continue;
    const double* p = i < kp_ ? &p_[static_cast<size_t>(i) * n] : zero_.data();
    const double* q = i >= ni - kq_ ? &q_[static_cast<size_t>(i - (ni - kq_)) * n] : zero_.data();
    tri_spike_row(n_, ia_.data(), ig_.data(), F_.data(), E_.data(), p, q, row(i + 1));
    emit(i + 1, out);
  }
  std::copy(F_.begin(), F_.end(), row(0));
  std::copy(E_.begin(), E_.end(), row(m_ - 1));
  emit(0, out);
  emit(m_ - 1, out);
}

void TridiagonalSolver::step(Vec u, double c, double theta) {
  factor(c, theta);
  apply(u, u, 1.0, explicit_part(c, theta));
}

// The owned planes of a ghosted local vector are layout A when the DMDA is split in slabs.
void TridiagonalSolver::step_local(Vec ulocal, double c, double theta) {
  step_local_begin(ulocal, c, theta);
  step_local_end(ulocal);
}

// local_ = the owned planes of ulocal (its array held until step_local_end), the factors set.
void TridiagonalSolver::map_local(Vec ulocal, double c, double theta) {
  if (!t_->direct()) throw std::logic_error("TridiagonalSolver::step_local: not slabs");
  factor(c, theta);
  const Box& gb = grid_.ghosted();
  const bool three = grid_.dim() == 3;
  MG_PETSC(VecGetArray(ulocal, &local_array_));
  local_.base =
      local_array_ + (three ? grid_.local_index(0, 0, a0_) : grid_.local_index(0, a0_, 0));
  local_.row = gb.m[0];
  local_.plane = three ? gb.m[0] * gb.m[1] : gb.m[0];
  local_.rows = three ? grid_.spec().n[1] : 1;
  local_.len = grid_.spec().n[0];
  in_place_ = rows_in_state(ulocal);
  if (!in_place_) rows_in_spectrum();
}

// The spectrum in place of the owned planes (row j from the start of owned plane j): where every
// plane's stride holds a spectral row and the last one ends within the array. The state plane j
// is then read by its transform (through the scratch plane) and not again; its final values
// overwrite the row once the row has been used. A row longer than the plane's owned cells (the
// DFT's n + 2 entries per x row) covers ghost cells: they are saved here and put back by
// restore_ghosts, so the ghosts stay untouched. Saves the spectrum's own pass through memory
// (2-D 1024^2 on 2 ranks: 4.2 MB per species and rank, which with the state outgrew the L3).
bool TridiagonalSolver::rows_in_state(Vec ulocal) {
  PetscInt size = 0;
  MG_PETSC(VecGetLocalSize(ulocal, &size));
  const std::ptrdiff_t first = local_.base - local_array_;
  if (local_.plane < n_ || first + (m_ - 1) * local_.plane + n_ > size) return false;
  rows_ = local_.base;
  row_stride_ = local_.plane;
  span_ghosts_.clear();
  for (std::ptrdiff_t o = 0; o < n_; ++o) // offsets in a row that are no owned cell of its plane
    if (o / local_.row >= local_.rows || o % local_.row >= local_.len) span_ghosts_.push_back(o);
  ghost_save_.resize(span_ghosts_.size() * static_cast<size_t>(m_));
  double* saved = ghost_save_.data();
  for (PetscInt j = 0; j < m_; ++j)
    for (std::ptrdiff_t o : span_ghosts_)
      *saved++ = row(j)[o];
  return true;
}

// The ghost cells the rows covered, back (after the last row went back to the state).
void TridiagonalSolver::restore_ghosts() {
  if (!in_place_) return;
  const double* saved = ghost_save_.data();
  for (PetscInt j = 0; j < m_; ++j)
    for (std::ptrdiff_t o : span_ghosts_)
      row(j)[o] = *saved++;
}

// Transform, elimination and back substitution; the reduced system's allgather posted.
void TridiagonalSolver::step_local_begin(Vec ulocal, double c, double theta) {
  map_local(ulocal, c, theta);
  down(local_, 1.0, explicit_part(c, theta));
  up(local_);
  ends_begin();
}

// step_local_begin of every member, their down passes in lockstep plane by plane; before(g) is
// called for every owned plane g (global index) before any member's transform reads it.
void TridiagonalSolver::step_local_group_begin(const std::vector<GroupMember>& group,
                                               const std::function<void(PetscInt)>& before) {
  if (group.empty()) return;
  TridiagonalSolver& first = *group.front().solver;
  const PetscInt a0 = first.a0_, m = first.m_;
  for (const GroupMember& g : group) {
    if (g.solver->a0_ != a0 || g.solver->m_ != m)
      throw std::logic_error("TridiagonalSolver::step_local_group_begin: different planes");
    g.solver->map_local(g.ulocal, g.c, g.theta);
  }
  before(a0);
  before(a0 + m - 1);
  for (const GroupMember& g : group)
    g.solver->down_begin(g.solver->local_, 1.0, explicit_part(g.c, g.theta));
  for (PetscInt j = 0; j < m; ++j) {
    if (j + 1 < m - 1) before(a0 + j + 1); // down_plane(j) reads plane j + 1 at the latest
    for (const GroupMember& g : group)
      g.solver->down_plane(g.solver->local_, j);
  }
  for (const GroupMember& g : group) {
    g.solver->down_end();
    g.solver->up(g.solver->local_);
    g.solver->ends_begin();
  }
}

void TridiagonalSolver::step_local_end(Vec ulocal) {
  ends(local_);
  restore_ghosts();
  MG_PETSC(VecRestoreArray(ulocal, &local_array_));
  local_array_ = nullptr;
  rows_in_spectrum();
}

void TridiagonalSolver::solve_shifted(Vec r, Vec x, double c, double theta) {
  factor(c, theta);
  apply(r, x, 1.0, 0.0);
}

} // namespace morphogen
