#include "grid/prolong.hpp"

namespace morphogen {

void prolong_cell_centred(const Grid& coarse, const double* c, const Grid& fine, double* f) {
  const Box& ob = fine.owned();
  const int dim = fine.dim();
  for (PetscInt K = ob.s[2]; K < ob.s[2] + ob.m[2]; ++K)
    for (PetscInt J = ob.s[1]; J < ob.s[1] + ob.m[1]; ++J)
      for (PetscInt I = ob.s[0]; I < ob.s[0] + ob.m[0]; ++I) {
        const PetscInt F[3] = {I, J, K};
        PetscInt p[3][2];
        double w[3][2];
        for (int d = 0; d < 3; ++d) {
          if (d >= dim) {
            p[d][0] = p[d][1] = F[d];
            w[d][0] = 1.0, w[d][1] = 0.0;
            continue;
          }
          p[d][0] = F[d] / 2;
          p[d][1] = p[d][0] + (F[d] % 2 == 0 ? -1 : 1);
          w[d][0] = 0.75, w[d][1] = 0.25;
        }
        double v = 0;
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            for (int e = 0; e < 2; ++e) {
              const double wt = w[0][a] * w[1][b] * w[2][e];
              if (wt != 0.0) v += wt * c[coarse.local_index(p[0][a], p[1][b], p[2][e])];
            }
        f[fine.local_index(I, J, K)] = v;
      }
}

} // namespace morphogen
