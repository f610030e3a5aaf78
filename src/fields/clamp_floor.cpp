#include "fields/clamp_floor.hpp"

#include <cmath>

namespace morphogen {

PetscInt apply_floor(const Grid& grid, std::vector<VecH>& u, const std::vector<double>& floor) {
  const Box& ob = grid.owned();
  PetscInt changed = 0;
  for (size_t s = 0; s < u.size(); ++s) {
    if (!std::isfinite(floor[s])) continue;
    PetscScalar* a = nullptr;
    MG_PETSC(VecGetArray(u[s], &a));
    for (PetscInt k = ob.s[2]; k < ob.s[2] + ob.m[2]; ++k)
      for (PetscInt j = ob.s[1]; j < ob.s[1] + ob.m[1]; ++j) {
        double* r = a + grid.local_index(ob.s[0], j, k);
        for (PetscInt i = 0; i < ob.m[0]; ++i)
          if (r[i] < floor[s]) r[i] = floor[s], ++changed; // NaN stays: the guard sees it
      }
    MG_PETSC(VecRestoreArray(u[s], &a));
  }
  return changed;
}

} // namespace morphogen
