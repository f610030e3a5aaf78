#include "grid/spectral_transform.hpp"

#include "grid/fft_planning.hpp"

#include <algorithm>
#include <fftw3.h>
#include <petscao.h>
#include <petscdmda.h>

namespace morphogen {

struct SpectralTransform::Plans {
  fftw_plan restF = nullptr, restB = nullptr, slowF = nullptr, slowB = nullptr;
  ~Plans() {
    for (fftw_plan p : {restF, restB, slowF, slowB})
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

SpectralTransform::SpectralTransform(const Grid& grid, const std::array<AxisKind, 3>& kinds)
    : plans_(std::make_unique<Plans>()) {
  int rank = 0;
  MPI_Comm_size(grid.comm(), &size_);
  MPI_Comm_rank(grid.comm(), &rank);
  const GridSpec& g = grid.spec();
  const int dim = grid.dim();
  bool all_periodic = true;
  for (int d = 0; d < dim; ++d) {
    all_periodic &= kinds[d] == AxisKind::Periodic;
    norm_ *= static_cast<double>(kinds[d] == AxisKind::Periodic ? g.n[d] : 2 * g.n[d]);
  }
  w_ = all_periodic ? 2 : 1;
  S_ = g.n[dim - 1];
  ncols_ = grid.global_cells() / S_;
  ncolsS_ = all_periodic ? ncols_ / g.n[0] * (g.n[0] / 2 + 1) : ncols_;
  a0_ = part(S_, size_, rank);
  a1_ = part(S_, size_, rank + 1);
  b0_ = size_ == 1 ? 0 : part(ncolsS_, size_, rank);
  nb_ = size_ == 1 ? ncolsS_ : part(ncolsS_, size_, rank + 1) - b0_;
  const size_t nA = static_cast<size_t>(a1_ - a0_);
  realA_ = fftw_alloc_real(std::max<size_t>(1, nA * ncols_));
  specA_ = fftw_alloc_real(std::max<size_t>(1, nA * ncolsS_ * w_));
  specB_ = size_ == 1 ? specA_ : fftw_alloc_real(std::max<size_t>(1, entries() * w_));
  fft_wisdom_load();
  plan(grid, kinds);
  if (fft_wisdom_sync(grid.comm())) { // again, from the wisdom every rank now shares
    plans_ = std::make_unique<Plans>();
    plan(grid, kinds);
  }
  if (size_ > 1) make_scatters(grid);
}

SpectralTransform::~SpectralTransform() {
  plans_.reset();
  vA_.reset();
  vSA_.reset();
  vSB_.reset();
  if (specB_ != specA_) fftw_free(specB_);
  fftw_free(specA_);
  fftw_free(realA_);
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
  if (howA > 0 && w_ == 2) {
    auto* cA = reinterpret_cast<fftw_complex*>(specA_);
    p.restF = fftw_plan_many_dft_r2c(nrest, rest, howA, realA_, nullptr, 1, nc, cA, nullptr, 1, ncS,
                                     flags);
    p.restB = fftw_plan_many_dft_c2r(nrest, rest, howA, cA, nullptr, 1, ncS, realA_, nullptr, 1, nc,
                                     flags);
  } else if (howA > 0) {
    p.restF = fftw_plan_many_r2r(nrest, rest, howA, realA_, nullptr, 1, nc, specA_, nullptr, 1, nc,
                                 kf + 1, flags);
    p.restB = fftw_plan_many_r2r(nrest, rest, howA, specA_, nullptr, 1, nc, realA_, nullptr, 1, nc,
                                 kb + 1, flags);
  }
  if (nb > 0 && w_ == 2) {
    auto* cB = reinterpret_cast<fftw_complex*>(specB_);
    p.slowF =
        fftw_plan_many_dft(1, &S, nb, cB, nullptr, nb, 1, cB, nullptr, nb, 1, FFTW_FORWARD, flags);
    p.slowB =
        fftw_plan_many_dft(1, &S, nb, cB, nullptr, nb, 1, cB, nullptr, nb, 1, FFTW_BACKWARD, flags);
  } else if (nb > 0) {
    p.slowF =
        fftw_plan_many_r2r(1, &S, nb, specB_, nullptr, nb, 1, specB_, nullptr, nb, 1, kf, flags);
    p.slowB =
        fftw_plan_many_r2r(1, &S, nb, specB_, nullptr, nb, 1, specB_, nullptr, nb, 1, kb, flags);
  }
}

// DMDA (PETSc order) -> layout A (natural order, slabs); layout A -> B (column slabs).
void SpectralTransform::make_scatters(const Grid& grid) {
  MPI_Comm comm = grid.comm();
  const PetscInt nA = (a1_ - a0_) * ncols_;
  MG_PETSC(VecCreateMPIWithArray(comm, 1, nA, PETSC_DECIDE, realA_, vA_.out()));
  std::vector<PetscInt> idx(static_cast<size_t>(nA));
  for (PetscInt i = 0; i < nA; ++i)
    idx[static_cast<size_t>(i)] = a0_ * ncols_ + i;
  AO ao;
  MG_PETSC(DMDAGetAO(grid.dm(), &ao));
  MG_PETSC(AOApplicationToPetsc(ao, nA, idx.data()));
  {
    IS from, to;
    MG_PETSC(ISCreateGeneral(comm, nA, idx.data(), PETSC_COPY_VALUES, &from));
    MG_PETSC(ISCreateStride(comm, nA, a0_ * ncols_, 1, &to));
    VecH u = grid.create_global();
    MG_PETSC(VecScatterCreate(u, from, vA_, to, toA_.out()));
    MG_PETSC(ISDestroy(&from));
    MG_PETSC(ISDestroy(&to));
  }
  const PetscInt nSA = (a1_ - a0_) * ncolsS_, nSB = S_ * nb_;
  MG_PETSC(VecCreateMPIWithArray(comm, w_, nSA * w_, PETSC_DECIDE, specA_, vSA_.out()));
  MG_PETSC(VecCreateMPIWithArray(comm, w_, nSB * w_, PETSC_DECIDE, specB_, vSB_.out()));
  std::vector<PetscInt> from_b(static_cast<size_t>(nSB)), to_b(static_cast<size_t>(nSB));
  size_t e = 0;
  for (PetscInt s = 0; s < S_; ++s)
    for (PetscInt c = b0_; c < b0_ + nb_; ++c, ++e) {
      from_b[e] = s * ncolsS_ + c;
      to_b[e] = S_ * b0_ + s * nb_ + (c - b0_);
    }
  IS from, to;
  MG_PETSC(ISCreateBlock(comm, w_, nSB, from_b.data(), PETSC_COPY_VALUES, &from));
  MG_PETSC(ISCreateBlock(comm, w_, nSB, to_b.data(), PETSC_COPY_VALUES, &to));
  MG_PETSC(VecScatterCreate(vSA_, from, vSB_, to, toB_.out()));
  MG_PETSC(ISDestroy(&from));
  MG_PETSC(ISDestroy(&to));
}

void SpectralTransform::forward(Vec u) {
  if (size_ == 1) {
    const PetscScalar* a;
    MG_PETSC(VecGetArrayRead(u, &a));
    std::copy(a, a + S_ * ncols_, realA_);
    MG_PETSC(VecRestoreArrayRead(u, &a));
  } else {
    MG_PETSC(VecScatterBegin(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
    MG_PETSC(VecScatterEnd(toA_, u, vA_, INSERT_VALUES, SCATTER_FORWARD));
  }
  run(plans_->restF);
  if (size_ > 1) {
    MG_PETSC(VecScatterBegin(toB_, vSA_, vSB_, INSERT_VALUES, SCATTER_FORWARD));
    MG_PETSC(VecScatterEnd(toB_, vSA_, vSB_, INSERT_VALUES, SCATTER_FORWARD));
  }
  run(plans_->slowF);
}

void SpectralTransform::backward(Vec u) {
  run(plans_->slowB);
  if (size_ > 1) {
    MG_PETSC(VecScatterBegin(toB_, vSB_, vSA_, INSERT_VALUES, SCATTER_REVERSE));
    MG_PETSC(VecScatterEnd(toB_, vSB_, vSA_, INSERT_VALUES, SCATTER_REVERSE));
  }
  run(plans_->restB);
  if (size_ == 1) {
    PetscScalar* a;
    MG_PETSC(VecGetArray(u, &a));
    std::copy(realA_, realA_ + S_ * ncols_, a);
    MG_PETSC(VecRestoreArray(u, &a));
  } else {
    MG_PETSC(VecScatterBegin(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
    MG_PETSC(VecScatterEnd(toA_, vA_, u, INSERT_VALUES, SCATTER_REVERSE));
  }
}

} // namespace morphogen
