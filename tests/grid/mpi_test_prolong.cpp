// Coarse-to-fine transfer for grid sequencing: exact on functions linear in each coordinate
// (with Dirichlet ghosts, which extrapolate linearly) in 2-D and 3-D, on any rank count with the
// fine grid nested in the coarse one (ranges doubled).
#include "../mpi_expect.hpp"
#include "grid/halo.hpp"
#include "grid/prolong.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace morphogen;
using morphogen::testing::max_over_ranks;

namespace {

double f(double x, double y, double z) {
  return 1.5 + 0.3 * x - 0.7 * y + 0.2 * z + 0.05 * x * y;
}

double check(int dim) {
  GridSpec cs;
  cs.dim = dim;
  cs.n = {10, 8, dim == 3 ? 6 : 1};
  cs.L = {2.0, 1.6, 1.2};
  cs.bc = {Boundary::Dirichlet, Boundary::Dirichlet, Boundary::Dirichlet};
  Grid coarse(PETSC_COMM_WORLD, cs);
  GridSpec fs = cs;
  for (int d = 0; d < dim; ++d)
    fs.n[d] *= 2;
  fs.ranges = coarse.ownership_ranges();
  for (auto& r : fs.ranges)
    for (auto& c : r)
      c *= 2;
  Grid fine(PETSC_COMM_WORLD, fs);
  Halo halo(coarse);
  const GridSpec& g = coarse.spec();
  VecH cv = coarse.create_local();
  PetscScalar* c;
  VecGetArray(cv, &c);
  const Box& ob = coarse.owned();
  const Box& gb = coarse.ghosted();
  auto xc = [&](const Grid& gr, int d, PetscInt i) { return d < dim ? gr.centre(d, i) : 0.0; };
  for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
    for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j)
      for (PetscInt i = ob.s[0]; i < ob.s[0] + ob.m[0]; ++i)
        c[coarse.local_index(i, j, k)] = f(xc(coarse, 0, i), xc(coarse, 1, j), xc(coarse, 2, k));
  // Dirichlet values: f on the faces (bilinear f: the 2g - u ghost is its exact extension
  // along the face normal).
  FaceValues fv;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      fv.face[2 * d + side].resize(static_cast<size_t>(halo.face_size(d)));
      for (PetscInt k = gb.s[2]; k < gb.s[2] + gb.m[2]; ++k)
        for (PetscInt j = gb.s[1]; j < gb.s[1] + gb.m[1]; ++j)
          for (PetscInt i = gb.s[0]; i < gb.s[0] + gb.m[0]; ++i) {
            double x[3] = {xc(coarse, 0, i), xc(coarse, 1, j), xc(coarse, 2, k)};
            x[d] = side == 0 ? 0.0 : g.L[d];
            fv.face[2 * d + side][halo.face_index(d, i, j, k)] = f(x[0], x[1], x[2]);
          }
    }
  halo.update(c, &fv);
  VecH fvh = fine.create_local();
  PetscScalar* fa;
  VecGetArray(fvh, &fa);
  prolong_cell_centred(coarse, c, fine, fa);
  double err = 0;
  const Box& fb = fine.owned();
  for (PetscInt k = fb.s[2]; k < fb.s[2] + fb.m[2]; ++k)
    for (PetscInt j = fb.s[1]; j < fb.s[1] + fb.m[1]; ++j)
      for (PetscInt i = fb.s[0]; i < fb.s[0] + fb.m[0]; ++i)
        err = std::max(err, std::abs(fa[fine.local_index(i, j, k)] -
                                     f(xc(fine, 0, i), xc(fine, 1, j), xc(fine, 2, k))));
  VecRestoreArray(fvh, &fa);
  VecRestoreArray(cv, &c);
  return max_over_ranks(err);
}

} // namespace

TEST(Prolong, ExactOnBilinear2D) {
  EXPECT_LT(check(2), 1e-12);
}
TEST(Prolong, ExactOnBilinear3D) {
  EXPECT_LT(check(3), 1e-12);
}
