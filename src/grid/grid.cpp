#include "grid/grid.hpp"

#include "core/user_error.hpp"

#include <petscdmda.h>

#include <cstdlib>
#include <new>

namespace morphogen {

const char* boundary_name(Boundary b) {
  switch (b) {
  case Boundary::Periodic:
    return "periodic";
  case Boundary::Neumann:
    return "neumann";
  case Boundary::Dirichlet:
    return "dirichlet";
  }
  return "?";
}

Grid::Grid(MPI_Comm comm, const GridSpec& spec) : spec_(spec) {
  if (spec.dim == 2) {
    spec_.n[2] = 1;
    spec_.L[2] = spec_.h(0);
    spec_.bc[2] = Boundary::Periodic;
  }
  auto dmbc = [&](int d) {
    return spec_.bc[d] == Boundary::Periodic ? DM_BOUNDARY_PERIODIC : DM_BOUNDARY_GHOSTED;
  };
  const DMDAStencilType st = spec.box_stencil ? DMDA_STENCIL_BOX : DMDA_STENCIL_STAR;
  // A grid too small for the rank count is a user error, not an internal one.
  const std::string err = petsc_quietly([&]() -> PetscErrorCode {
    const bool fixed = !spec.ranges[0].empty();
    const auto count = [&](int d) {
      return fixed ? static_cast<PetscInt>(spec.ranges[d].size()) : PETSC_DECIDE;
    };
    const auto lx = [&](int d) { return fixed ? spec.ranges[d].data() : nullptr; };
    if (spec.dim == 2)
      PetscCall(DMDACreate2d(comm, dmbc(0), dmbc(1), st, spec_.n[0], spec_.n[1], count(0), count(1),
                             1, spec.stencil_width, lx(0), lx(1), dm_.out()));
    else
      PetscCall(DMDACreate3d(comm, dmbc(0), dmbc(1), dmbc(2), st, spec_.n[0], spec_.n[1],
                             spec_.n[2], count(0), count(1), count(2), 1, spec.stencil_width, lx(0),
                             lx(1), lx(2), dm_.out()));
    PetscCall(DMSetUp(dm_));
    return 0;
  });
  if (!err.empty()) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    std::string n = std::to_string(spec_.n[0]);
    for (int d = 1; d < spec.dim; ++d)
      n += "," + std::to_string(spec_.n[d]);
    throw UserError("-grid_n " + n + ": cannot be split over " + std::to_string(size) +
                    " ranks (each rank needs at least " + std::to_string(spec.stencil_width) +
                    " cells per axis; PETSc: " + err + ")");
  }
  // No DMDA coordinates: cell centres follow from the index ((i + 1/2) h), and a coordinate
  // vector with its scatter would cost 24 bytes per cell in 2-D.
  MG_PETSC(DMDAGetCorners(dm_, &owned_.s[0], &owned_.s[1], &owned_.s[2], &owned_.m[0], &owned_.m[1],
                          &owned_.m[2]));
  MG_PETSC(DMDAGetGhostCorners(dm_, &ghosted_.s[0], &ghosted_.s[1], &ghosted_.s[2], &ghosted_.m[0],
                               &ghosted_.m[1], &ghosted_.m[2]));
}

MPI_Comm Grid::comm() const {
  return PetscObjectComm(reinterpret_cast<PetscObject>(dm_.get()));
}

namespace {

PetscErrorCode free_aligned(void* p) {
  std::free(p);
  return 0;
}

} // namespace

// What DMCreateLocalVector makes for a DMDA of the standard vector type (a sequential vector
// of the ghosted box, its DM set), with the owned box's first cell on a 64-byte boundary: with
// an even ghosted row length every owned row is then 16-byte aligned, which FFTW's plane
// transforms need to read and write the state's rows in place (one ghost cell before each row
// would put every row 8 bytes off). The array lives as long as the vector (a composed container).
VecH Grid::create_local() const {
  VecH v;
  VecType type = nullptr;
  MG_PETSC(DMGetVecType(dm_, &type));
  PetscBool standard = PETSC_FALSE, seq = PETSC_FALSE;
  MG_PETSC(PetscStrcmp(type, VECSTANDARD, &standard));
  MG_PETSC(PetscStrcmp(type, VECSEQ, &seq));
  if (!standard && !seq) {
    MG_PETSC(DMCreateLocalVector(dm_, v.out()));
    MG_PETSC(VecSet(v, 0.0));
    return v;
  }
  const size_t n = static_cast<size_t>(ghosted_.size());
  const size_t lead = static_cast<size_t>(local_index(owned_.s[0], owned_.s[1], owned_.s[2]));
  const size_t shift = (8 - lead % 8) % 8; // doubles: owned start on a 64-byte line
  void* raw = std::aligned_alloc(64, (8 * (n + shift) + 63) / 64 * 64);
  if (!raw) throw std::bad_alloc();
  PetscContainer keep = nullptr;
  MG_PETSC(PetscContainerCreate(PETSC_COMM_SELF, &keep));
  MG_PETSC(PetscContainerSetPointer(keep, raw));
  MG_PETSC(PetscContainerSetUserDestroy(keep, free_aligned));
  const PetscErrorCode rc = VecCreateSeqWithArray(PETSC_COMM_SELF, 1, static_cast<PetscInt>(n),
                                                  static_cast<PetscScalar*>(raw) + shift, v.out());
  if (!rc)
    MG_PETSC(PetscObjectCompose(reinterpret_cast<PetscObject>(v.get()), "morphogen_array",
                                reinterpret_cast<PetscObject>(keep)));
  MG_PETSC(PetscContainerDestroy(&keep)); // frees raw here unless the vector holds it
  MG_PETSC(rc);
  MG_PETSC(VecSetDM(v, dm_));
  MG_PETSC(VecSet(v, 0.0));
  return v;
}

std::array<std::vector<PetscInt>, 3> Grid::ownership_ranges() const {
  PetscInt P[3] = {1, 1, 1};
  MG_PETSC(DMDAGetInfo(dm_, nullptr, nullptr, nullptr, nullptr, &P[0], &P[1], &P[2], nullptr,
                       nullptr, nullptr, nullptr, nullptr, nullptr));
  const PetscInt* l[3] = {nullptr, nullptr, nullptr};
  MG_PETSC(DMDAGetOwnershipRanges(dm_, &l[0], &l[1], &l[2]));
  std::array<std::vector<PetscInt>, 3> r;
  for (int d = 0; d < spec_.dim; ++d)
    r[d].assign(l[d], l[d] + P[d]);
  return r;
}

std::array<Grid::AxisRanges, 3> Grid::axis_ranges() const {
  const auto l = ownership_ranges();
  std::array<AxisRanges, 3> ax;
  for (int d = 0; d < 3; ++d) {
    const std::vector<PetscInt> counts = d < spec_.dim ? l[d] : std::vector<PetscInt>{1};
    for (PetscInt p = 0, s = 0; p < static_cast<PetscInt>(counts.size()); ++p) {
      ax[d].start.push_back(s);
      ax[d].count.push_back(counts[p]);
      s += counts[p];
    }
  }
  return ax;
}

VecH Grid::create_global() const {
  VecH v;
  MG_PETSC(DMCreateGlobalVector(dm_, v.out()));
  MG_PETSC(VecSet(v, 0.0));
  return v;
}

} // namespace morphogen
