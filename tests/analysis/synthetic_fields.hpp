// Synthetic 2-D fields with known structure, shared by the analysis unit tests
// (test_pattern_metrics.cpp, test_classify.cpp): header-only, inline, in morphogen::testing.
//
// Field             a scalar field on a cell-centred nx x ny grid (x fastest) and its
//                   FieldShape2D; at(i, j) is cell (i, j).
// make(nx, ny, h)   an all-zero field, spacing h on both axes, periodic on both axes.
// hexagonal(h)      hexagonal spots on a 128 x 148 torus, spacing h: the sum of three cosines
//                   cos(k1.x) + cos(k2.x) + cos(k3.x) with k1 = 2 pi (8/Lx, 0),
//                   k2,3 = 2 pi (-4/Lx, +-8/Ly) at the cell centres x = (i + 1/2) h,
//                   y = (j + 1/2) h (Lx = 128 h, Ly = 148 h): |k2| / |k1| = 0.9991 (a 0.09 %
//                   departure from 120 degrees, the closest integer lattice), exactly periodic,
//                   wavelength 16 cells, det [[8, 0], [-4, 8]] = 64 maxima.
// stripes(n, a, b)  plane-wave stripes cos(2 pi (a (i + 1/2) + b (j + 1/2)) / n) on an n x n
//                   torus of unit spacing: wave vector (a, b) cycles per n cells, commensurate
//                   with the torus, wavelength n / |(a, b)| cells.
#pragma once

#include "analysis/pattern_metrics.hpp"

#include <cmath>
#include <cstddef>
#include <vector>

namespace morphogen::testing {

inline constexpr double kPi = 3.14159265358979323846;

struct Field {
  analysis::FieldShape2D shape;
  std::vector<double> u;
  double& at(int i, int j) { return u[i + static_cast<std::size_t>(shape.nx) * j]; }
};

inline Field make(int nx, int ny, double h = 1.0) {
  Field f;
  f.shape = analysis::FieldShape2D{nx, ny, h, h, true, true};
  f.u.assign(static_cast<std::size_t>(nx) * ny, 0.0);
  return f;
}

inline Field hexagonal(double h = 1.0) {
  Field f = make(128, 148, h);
  const double Lx = 128 * h, Ly = 148 * h;
  for (int j = 0; j < 148; ++j)
    for (int i = 0; i < 128; ++i) {
      const double x = (i + 0.5) * h, y = (j + 0.5) * h;
      f.at(i, j) = std::cos(2 * kPi * 8 * x / Lx) + std::cos(2 * kPi * (-4 * x / Lx + 8 * y / Ly)) +
                   std::cos(2 * kPi * (-4 * x / Lx - 8 * y / Ly));
    }
  return f;
}

inline Field stripes(int n, int a, int b) {
  Field f = make(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      f.at(i, j) = std::cos(2 * kPi * (a * (i + 0.5) + b * (j + 0.5)) / n);
  return f;
}

} // namespace morphogen::testing
