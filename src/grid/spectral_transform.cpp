#include "grid/spectral_transform.hpp"

#include "core/user_error.hpp"
#include "grid/fft_planning.hpp"
#include "grid/trig_transform.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <fftw3.h>
#include <petscao.h>
#include <petscdmda.h>
#include <string>

namespace morphogen {

struct SpectralTransform::Plans {
  fftw_plan restF = nullptr, restB = nullptr, slowF = nullptr, slowB = nullptr;
  fftw_plan planeF = nullptr, planeB = nullptr; // one plane of T_rest (rest_only)
  // Instead, where no rest axis is periodic: rows of cosines or sines along x (and, in 3-D,
  // the plane's columns along y, all at once).
  std::unique_ptr<TrigTransform> trig, trig_cols;
  std::unique_ptr<TrigTransform> trig_slow; // the columns of layout B, not periodic
  ~Plans() {
    for (fftw_plan p : {restF, restB, slowF, slowB, planeF, planeB})
      if (p) fftw_destroy_plan(p);
  }
};

namespace {

PetscInt part(PetscInt n, int parts, int r) {
  return static_cast<PetscInt>(static_cast<long long>(n) * r / parts);
}

void run(fftw_plan p) {
  if (p) fftw_execute(p);
}

} // namespace

std::array<AxisKind, 3> axis_kinds(const Grid& grid) {
  std::array<AxisKind, 3> k{};
  for (int d = 0; d < 3; ++d)
    k[d] = grid.spec().bc[d] == Boundary::Periodic  ? AxisKind::Periodic
           : grid.spec().bc[d] == Boundary::Neumann ? AxisKind::Even
                                                    : AxisKind::Odd;
  return k;
}

SpectralTransform::SpectralTransform(const Grid& grid, const std::array<AxisKind, 3>& kinds,
                                     bool rest_only)
    : rest_only_(rest_only), plans_(std::make_unique<Plans>()) {
  int rank = 0;
  MPI_Comm_size(grid.comm(), &size_);
  MPI_Comm_rank(grid.comm(), &rank);
  const GridSpec& g = grid.spec();
  const int dim = grid.dim();
  bool all_periodic = true;
  for (int d = 0; d < (rest_only ? dim - 1 : dim); ++d) {
    all_periodic &= kinds[d] == AxisKind::Periodic;
    norm_ *= static_cast<double>(kinds[d] == AxisKind::Periodic ? g.n[d] : 2 * g.n[d]);
  }
  w_ = all_periodic ? 2 : 1;
  S_ = g.n[dim - 1];
  nx_ = g.n[0];
  ncols_ = grid.global_cells() / S_;
  ncolsS_ = all_periodic ? ncols_ / g.n[0] * (g.n[0] / 2 + 1) : ncols_;
  comm_ = grid.comm();
  rank_ = rank;
  slab_ranges(grid);
  const size_t nA = static_cast<size_t>(a1_ - a0_);
  realA_ = fftw_alloc_real(std::max<size_t>(1, nA * ncols_));
  specA_ = fftw_alloc_real(std::max<size_t>(1, nA * ncolsS_ * w_));
  specB_ = size_ == 1 || rest_only_ ? specA_ : fftw_alloc_real(std::max<size_t>(1, entries() * w_));
  if (rest_only_) {
    planeR_ = fftw_alloc_real(static_cast<size_t>(ncols_));
    planeS_ = fftw_alloc_real(static_cast<size_t>(ncolsS_) * static_cast<size_t>(w_));
  }
  fft_wisdom_load();
  plan(grid, kinds);
  if (fft_wisdom_sync(grid.comm())) { // again, from the wisdom every rank now shares
    plans_ = std::make_unique<Plans>();
    plan(grid, kinds);
  }
  if (!direct_) make_scatter(grid);
  if (size_ > 1 && !rest_only_) transpose_counts();
}

// Layout A's planes: the DMDA's own slow-axis ranges when every rank owns whole planes (layout
// A is then the DMDA vector), an even split otherwise. Spectral columns: an even split.
void SpectralTransform::slab_ranges(const Grid& grid) {
  const int dim = grid.dim();
  const Box& ob = grid.owned();
  int whole = 1;
  for (int d = 0; d < dim - 1; ++d)
    whole &= ob.s[d] == 0 && ob.m[d] == grid.spec().n[d] ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &whole, 1, MPI_INT, MPI_LAND, comm_);
  direct_ = whole != 0;
  aparts_.assign(static_cast<size_t>(size_) + 1, S_);
  bparts_.assign(static_cast<size_t>(size_) + 1, ncolsS_);
  if (direct_) {
    PetscInt first = ob.s[dim - 1];
    MPI_Allgather(&first, 1, MPIU_INT, aparts_.data(), 1, MPIU_INT, comm_);
  }
  for (int r = 0; r < size_; ++r) {
    if (!direct_) aparts_[static_cast<size_t>(r)] = part(S_, size_, r);
    bparts_[static_cast<size_t>(r)] = part(ncolsS_, size_, r);
  }
  a0_ = aparts_[static_cast<size_t>(rank_)];
  a1_ = aparts_[static_cast<size_t>(rank_) + 1];
  b0_ = bparts_[static_cast<size_t>(rank_)];
  nb_ = bparts_[static_cast<size_t>(rank_) + 1] - b0_;
}

// Counts and displacements (doubles) of the transposes: the packed block of this rank's planes
// for rank q (pack: A -> B sends these, B -> A receives them) and the rows of B that rank p's
// planes fill (rows: A -> B receives, B -> A sends). This rank's own block is copied directly.
void SpectralTransform::transpose_counts() {
  const long long w = w_, nA = a1_ - a0_;
  scount_.assign(static_cast<size_t>(size_), 0);
  sdispl_ = rcount_ = rdispl_ = scount_;
  long long off = 0;
  for (int q = 0; q < size_; ++q) {
    const size_t uq = static_cast<size_t>(q);
    const long long pack = q == rank_ ? 0 : nA * (bparts_[uq + 1] - bparts_[uq]) * w;
    const long long rows = q == rank_ ? 0 : (aparts_[uq + 1] - aparts_[uq]) * nb_ * w;
    if (off + pack > INT_MAX || aparts_[uq + 1] * nb_ * w > INT_MAX)
      throw UserError("spectral solve: more than 2^31 spectral values on one rank (grid " +
                      std::to_string(S_) + " planes); use more ranks or -diffusion_solver ksp");
    scount_[uq] = static_cast<int>(pack);
    sdispl_[uq] = static_cast<int>(off);
    rcount_[uq] = static_cast<int>(rows);
    rdispl_[uq] = static_cast<int>(aparts_[uq] * nb_ * w);
    off += pack;
  }
  xbuf_.resize(static_cast<size_t>(std::max(1LL, off)));
}

// Copies between this rank's planes of layout A and the blocks of the transposes: the block
// of columns of rank q goes to (to_b) or comes from its packed place in xbuf, this rank's own
// block to or from its rows of B directly.
void SpectralTransform::copy_blocks(bool to_b) {
  const size_t w = static_cast<size_t>(w_), nA = static_cast<size_t>(a1_ - a0_);
  const size_t rowA = static_cast<size_t>(ncolsS_) * w, rowB = static_cast<size_t>(nb_) * w;
  for (int q = 0; q < size_; ++q) {
    const size_t uq = static_cast<size_t>(q);
    const size_t c0 = static_cast<size_t>(bparts_[uq]) * w;
    const size_t len = static_cast<size_t>(bparts_[uq + 1] - bparts_[uq]) * w;
    for (size_t s = 0; s < nA; ++s) {
      double* a = specA_ + s * rowA + c0;
      double* o = q == rank_ ? specB_ + (static_cast<size_t>(a0_) + s) * rowB
                             : xbuf_.data() + static_cast<size_t>(sdispl_[uq]) + s * len;
      if (to_b)
        std::copy(a, a + len, o);
      else
        std::copy(o, o + len, a);
    }
  }
}

// A -> B: the blocks packed by destination, one MPI_Alltoallv whose blocks land as rows of B.
void SpectralTransform::to_columns() {
  copy_blocks(true);
  MPI_Alltoallv(xbuf_.data(), scount_.data(), sdispl_.data(), MPI_DOUBLE, specB_, rcount_.data(),
                rdispl_.data(), MPI_DOUBLE, comm_);
}

// B -> A: one MPI_Alltoallv of whole rows of B, then each block unpacked into its columns.
void SpectralTransform::from_columns() {
  MPI_Alltoallv(specB_, rcount_.data(), rdispl_.data(), MPI_DOUBLE, xbuf_.data(), scount_.data(),
                sdispl_.data(), MPI_DOUBLE, comm_);
  copy_blocks(false);
}

SpectralTransform::~SpectralTransform() {
  plans_.reset();
  toA_.reset();
  vA_.reset();
  if (specB_ != specA_) fftw_free(specB_);
  fftw_free(specA_);
  fftw_free(realA_);
  fftw_free(planeR_);
  fftw_free(planeS_);
}

// T_rest over this rank's planes of layout A; T_slow along the strided columns of layout B.
void SpectralTransform::plan(const Grid& grid, const std::array<AxisKind, 3>& kinds) {
  const GridSpec& g = grid.spec();
  const int dim = grid.dim(), nrest = dim - 1;
  int rest[2];
  fftw_r2r_kind kf[3], kb[3];
  for (int r = 0; r < nrest; ++r) // C order: slowest of the rest first
    rest[r] = static_cast<int>(g.n[nrest - 1 - r]);
  for (int r = 0; r < dim; ++r) { // kinds in C order (slow axis first)
    const AxisKind k = kinds[dim - 1 - r];
    kf[r] = k == AxisKind::Periodic ? FFTW_R2HC : k == AxisKind::Even ? FFTW_REDFT10 : FFTW_RODFT10;
    kb[r] = k == AxisKind::Periodic ? FFTW_HC2R : k == AxisKind::Even ? FFTW_REDFT01 : FFTW_RODFT01;
  }
  const int howA = static_cast<int>(a1_ - a0_), nb = static_cast<int>(nb_);
  const int S = static_cast<int>(S_), nc = static_cast<int>(ncols_),
            ncS = static_cast<int>(ncolsS_);
  const unsigned flags = fft_planner_flags();
  Plans& p = *plans_;
  const bool trig_rest =
      w_ == 1 && kinds[0] != AxisKind::Periodic && (nrest == 1 || kinds[1] != AxisKind::Periodic);
  if (trig_rest) {
    p.trig = std::make_unique<TrigTransform>(rest[nrest - 1], kinds[0] == AxisKind::Odd, flags);
    if (nrest == 2)
      p.trig_cols =
          std::make_unique<TrigTransform>(rest[0], kinds[1] == AxisKind::Odd, flags, rest[1]);
  }
  if (howA > 0 && w_ == 2) {
    auto* cA = reinterpret_cast<fftw_complex*>(specA_);
    p.restF = fftw_plan_many_dft_r2c(nrest, rest, howA, realA_, nullptr, 1, nc, cA, nullptr, 1, ncS,
                                     flags);
    p.restB = fftw_plan_many_dft_c2r(nrest, rest, howA, cA, nullptr, 1, ncS, realA_, nullptr, 1, nc,
                                     flags);
  } else if (howA > 0 && !trig_rest) {
    p.restF = fftw_plan_many_r2r(nrest, rest, howA, realA_, nullptr, 1, nc, specA_, nullptr, 1, nc,
                                 kf + 1, flags);
    p.restB = fftw_plan_many_r2r(nrest, rest, howA, specA_, nullptr, 1, nc, realA_, nullptr, 1, nc,
                                 kb + 1, flags);
  }
  if (rest_only_ && w_ == 2) {
    auto* cS = reinterpret_cast<fftw_complex*>(planeS_);
    p.planeF = fftw_plan_dft_r2c(nrest, rest, planeR_, cS, flags);
    p.planeB = fftw_plan_dft_c2r(nrest, rest, cS, planeR_, flags);
  } else if (rest_only_ && !trig_rest) {
    p.planeF = fftw_plan_r2r(nrest, rest, planeR_, planeS_, kf + 1, flags);
    p.planeB = fftw_plan_r2r(nrest, rest, planeS_, planeR_, kb + 1, flags);
  }
  if (rest_only_) return;
  if (nb > 0 && w_ == 2) {
    auto* cB = reinterpret_cast<fftw_complex*>(specB_);
    p.slowF =
        fftw_plan_many_dft(1, &S, nb, cB, nullptr, nb, 1, cB, nullptr, nb, 1, FFTW_FORWARD, flags);
    p.slowB =
        fftw_plan_many_dft(1, &S, nb, cB, nullptr, nb, 1, cB, nullptr, nb, 1, FFTW_BACKWARD, flags);
  } else if (nb > 0 && kinds[dim - 1] != AxisKind::Periodic) {
    p.trig_slow = std::make_unique<TrigTransform>(S, kinds[dim - 1] == AxisKind::Odd, flags, nb);
  } else if (nb > 0) {
    p.slowF =
        fftw_plan_many_r2r(1, &S, nb, specB_, nullptr, nb, 1, specB_, nullptr, nb, 1, kf, flags);
    p.slowB =
        fftw_plan_many_r2r(1, &S, nb, specB_, nullptr, nb, 1, specB_, nullptr, nb, 1, kb, flags);
  }
}

// DMDA (PETSc order) -> layout A (natural order, slabs), for a DMDA not split in slabs.
void SpectralTransform::make_scatter(const Grid& grid) {
  MPI_Comm comm = grid.comm();
  const PetscInt nA = (a1_ - a0_) * ncols_;
  MG_PETSC(VecCreateMPIWithArray(comm, 1, nA, PETSC_DECIDE, realA_, vA_.out()));
  std::vector<PetscInt> idx(static_cast<size_t>(nA));
  for (PetscInt i = 0; i < nA; ++i)
    idx[static_cast<size_t>(i)] = a0_ * ncols_ + i;
  AO ao;
  MG_PETSC(DMDAGetAO(grid.dm(), &ao));
  MG_PETSC(AOApplicationToPetsc(ao, nA, idx.data()));
  IS from, to;
  MG_PETSC(ISCreateGeneral(comm, nA, idx.data(), PETSC_COPY_VALUES, &from));
  MG_PETSC(ISCreateStride(comm, nA, a0_ * ncols_, 1, &to));
  VecH u = grid.create_global();
  MG_PETSC(VecScatterCreate(u, from, vA_, to, toA_.out()));
  MG_PETSC(ISDestroy(&from));
  MG_PETSC(ISDestroy(&to));
}

// T_rest from the DMDA vector u into specA (directly from u's array when layout A is u's part
// and FFTW's alignment of the two arrays agrees or the planes are TrigTransform's, else
// through realA).
void SpectralTransform::rest_forward(Vec u) {
  const PetscScalar* a = nullptr;
  double* in = realA_;
  if (!direct_) {
    MG_PETSC(VecScatterBegin(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
    MG_PETSC(VecScatterEnd(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
  } else {
    MG_PETSC(VecGetArrayRead(u, &a));
    if (fftw_alignment_of(const_cast<double*>(a)) == fftw_alignment_of(realA_) || plans_->trig)
      in = const_cast<double*>(a); // FFTW's forward out-of-place plans preserve their input
    else
      std::copy(a, a + (a1_ - a0_) * ncols_, realA_);
  }
  if (plans_->trig)
    for (PetscInt s = 0; s < a1_ - a0_; ++s)
      trig_plane_forward(in + s * ncols_, nx_, ncols_ / nx_, specA_ + s * ncols_);
  else if (plans_->restF && w_ == 2)
    fftw_execute_dft_r2c(plans_->restF, in, reinterpret_cast<fftw_complex*>(specA_));
  else if (plans_->restF)
    fftw_execute_r2r(plans_->restF, in, specA_);
  if (a) MG_PETSC(VecRestoreArrayRead(u, &a));
}

// T_rest^-1 from specA (destroyed) into the DMDA vector u.
void SpectralTransform::rest_backward(Vec u) {
  PetscScalar* a = nullptr;
  double* out = realA_;
  if (direct_) {
    MG_PETSC(VecGetArray(u, &a));
    if (fftw_alignment_of(a) == fftw_alignment_of(realA_) || plans_->trig) out = a;
  }
  if (plans_->trig)
    for (PetscInt s = 0; s < a1_ - a0_; ++s)
      trig_plane_backward(specA_ + s * ncols_, out + s * ncols_, nx_, ncols_ / nx_);
  else if (plans_->restB && w_ == 2)
    fftw_execute_dft_c2r(plans_->restB, reinterpret_cast<fftw_complex*>(specA_), out);
  else if (plans_->restB)
    fftw_execute_r2r(plans_->restB, specA_, out);
  if (a) {
    if (out != a) std::copy(realA_, realA_ + (a1_ - a0_) * ncols_, a);
    MG_PETSC(VecRestoreArray(u, &a));
  } else {
    MG_PETSC(VecScatterBegin(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
    MG_PETSC(VecScatterEnd(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
  }
}

void SpectralTransform::forward(Vec u) {
  rest_forward(u);
  if (size_ > 1 && !rest_only_) to_columns();
  if (plans_->trig_slow) plans_->trig_slow->forward(specB_, specB_);
  run(plans_->slowF);
}

void SpectralTransform::backward(Vec u) {
  if (plans_->trig_slow) plans_->trig_slow->backward(specB_, specB_);
  run(plans_->slowB);
  if (size_ > 1 && !rest_only_) from_columns();
  rest_backward(u);
}

PlaneView SpectralTransform::reals(Vec u, bool fetch) {
  PlaneView v{realA_, ncols_, nx_, ncols_ / nx_, nx_};
  if (!direct_) {
    if (fetch) {
      MG_PETSC(VecScatterBegin(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
      MG_PETSC(VecScatterEnd(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
    }
    return v;
  }
  MG_PETSC(VecGetArray(u, &v.base));
  return v;
}

void SpectralTransform::reals_done(Vec u, const PlaneView& v, bool store) {
  if (direct_) {
    PetscScalar* a = v.base;
    MG_PETSC(VecRestoreArray(u, &a));
  } else if (store) {
    MG_PETSC(VecScatterBegin(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
    MG_PETSC(VecScatterEnd(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
  }
}

// Whether a spectrum of n entries at spec shares memory with plane p of v (addresses compared as
// integers: the two may point into different arrays).
static bool overlaps(const double* spec, PetscInt n, const double* p, const PlaneView& v) {
  const auto a = reinterpret_cast<std::uintptr_t>(spec), b = reinterpret_cast<std::uintptr_t>(p);
  const auto plane_bytes = sizeof(double) * static_cast<size_t>((v.rows - 1) * v.row + v.len);
  return a < b + plane_bytes && b < a + sizeof(double) * static_cast<size_t>(n);
}

// The plane plans were made for contiguous FFTW-aligned planes. The forward transform reads a
// plane in place where it is one (the state's rows: Grid::create_local aligns them); any other
// plane goes through the scratch plane, and so does the spectrum where it overlaps the plane
// (TridiagonalSolver's rows in the state). The inverse always writes the scratch plane, then copies
// it out: a c2r transform also uses its output as work space, which is cheaper in a plane that
// stays in L1 than in the state (2-D, 1024^2, 2 ranks: the diffusion substep 1-3 % faster than
// writing aligned rows in place; the same bits either way). Planes of cosines and sines (no rest
// axis periodic) are transformed by TrigTransform, rows from and to the state, then the
// plane's columns (3-D) in the spectrum (first copied to the scratch plane where it overlaps the
// plane the rows go to).
void SpectralTransform::plane_forward(const PlaneView& v, PetscInt j, double* spec) {
  const double* p = v.base + j * v.plane;
  const PetscInt ns = ncolsS_ * w_;
  const bool overlap = overlaps(spec, ns, p, v); // a spectrum in place of the plane
  if (plans_->trig) {
    trig_plane_forward(p, v.row, v.rows, overlap ? planeS_ : spec);
    if (overlap) std::copy(planeS_, planeS_ + ns, spec);
    return;
  }
  double* in = const_cast<double*>(p); // forward out-of-place plans preserve their input
  if (!((v.rows == 1 || v.row == v.len) && fftw_alignment_of(in) == 0)) {
    for (PetscInt r = 0; r < v.rows; ++r)
      std::copy(p + r * v.row, p + r * v.row + v.len, planeR_ + r * v.len);
    in = planeR_;
  }
  double* out = fftw_alignment_of(spec) == 0 && !overlap ? spec : planeS_;
  if (w_ == 2)
    fftw_execute_dft_r2c(plans_->planeF, in, reinterpret_cast<fftw_complex*>(out));
  else
    fftw_execute_r2r(plans_->planeF, in, out);
  if (out != spec) std::copy(planeS_, planeS_ + ns, spec);
}

void SpectralTransform::plane_backward(double* spec, const PlaneView& v, PetscInt j) {
  const PetscInt ns = ncolsS_ * w_;
  double* p = v.base + j * v.plane;
  if (plans_->trig) {
    if (overlaps(spec, ns, p, v)) // the rows below would overwrite the spectrum as they go
      spec = std::copy(spec, spec + ns, planeS_) - ns;
    return trig_plane_backward(spec, p, v.row, v.rows);
  }
  double* in = fftw_alignment_of(spec) == 0 ? spec : std::copy(spec, spec + ns, planeS_) - ns;
  if (w_ == 2)
    fftw_execute_dft_c2r(plans_->planeB, reinterpret_cast<fftw_complex*>(in), planeR_);
  else
    fftw_execute_r2r(plans_->planeB, in, planeR_);
  for (PetscInt r = 0; r < v.rows; ++r)
    std::copy(planeR_ + r * v.len, planeR_ + (r + 1) * v.len, p + r * v.row);
}

// A plane of cosines and sines: rows (`rows` of nx_ cells, `row` apart) to or from the plane's
// spectrum (rows of nx_), whose columns are transformed in place (3-D).
void SpectralTransform::trig_plane_forward(const double* p, std::ptrdiff_t row, PetscInt rows,
                                           double* spec) {
  for (PetscInt r = 0; r < rows; ++r)
    plans_->trig->forward(p + r * row, spec + r * nx_);
  if (plans_->trig_cols) plans_->trig_cols->forward(spec, spec);
}

void SpectralTransform::trig_plane_backward(double* spec, double* p, std::ptrdiff_t row,
                                            PetscInt rows) {
  if (plans_->trig_cols) plans_->trig_cols->backward(spec, spec);
  for (PetscInt r = 0; r < rows; ++r)
    plans_->trig->backward(spec + r * nx_, p + r * row);
}

} // namespace morphogen
