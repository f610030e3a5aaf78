// Semi-Lagrangian advection kernels (stable-ARD paper eqs. 18-20; Stam 1999): the transport
// dA/dt = -(u . grad) A over one step is A^{n+1}(x_c) = A~(X), the intermediate field (after
// reaction and diffusion) interpolated at the departure point X of the characteristic that
// arrives at the cell centre x_c:
//   euler (eq. 20)    X = x_c - dt u(x_c)
//   rk2 (midpoint)    X = x_c - dt u(x_c - dt/2 u(x_c))   (u interpolated linearly at the midpoint)
// Pure kernels: no PETSc, MPI, allocation or exceptions.
//
// Positions are in cell-index units along each axis (cell i's centre is at i), in global
// indices unwrapped along periodic axes. Fields are read from a wide box (WideGeom, the
// layout of grid/wide_halo.hpp) that holds the periodic images, so a periodic position needs no
// wrap; along a non-periodic axis a position is clamped to [0, n-1] (the boundary cells' centres:
// a back-trace leaving the domain takes the nearest boundary value, walls and Dirichlet alike).
//
// Interpolation:
//   linear  (bi/trilinear) from the 2^dim cells around X: exact for linear fields, error
//           O(h^2); a convex combination, so it never creates new extrema (max principle).
//   cubic   tensor-product 4-point Lagrange from the 4^dim cells i0-1..i0+2 (exact for cubics,
//           error O(h^4)); it can overshoot near steep fronts. Along a non-periodic axis the
//           stencil's indices are clamped into [0, n-1] (boundary values repeated).
// A back-trace of Courant number C = max_d |u_d| dt / h_d reads at most floor(C) + 2 cells
// (linear) or floor(C) + 3 (cubic) beyond the arrival cell (advection_reach; floor(C) + 1 >=
// ceil(C) covers the rounding of a departure point at an integer Courant number).
#pragma once

#include "models/model.hpp" // MG_HD

#include <cmath>

namespace morphogen::advect {

enum class Interp { Linear, Cubic };
enum class Backtrace { Euler, Rk2 };

// The wide box of a rank (global indices, x fastest) and the grid's axes.
struct WideGeom {
  int dim = 2;
  long long n[3] = {1, 1, 1}; // global cells per axis
  bool periodic[3] = {true, true, true};
  long long s[3] = {0, 0, 0}; // first cell of the box per axis
  long long m[3] = {1, 1, 1}; // extent of the box per axis
  MG_HD long long index(long long i, long long j, long long k) const {
    return (i - s[0]) + m[0] * ((j - s[1]) + m[1] * (k - s[2]));
  }
};

// Halo width (cells) a back-trace of Courant number `courant` needs. A Courant number beyond
// 1e9 (or not finite) is capped there: far wider than any halo, and no overflowing cast.
MG_HD inline long long advection_reach(double courant, Interp interp) {
  const double c = courant < 1e9 ? courant : 1e9;
  return static_cast<long long>(std::floor(c)) + (interp == Interp::Cubic ? 3 : 2);
}

// Position along axis d clamped to the boundary cells' centres on a non-periodic axis.
MG_HD inline double clamp_position(const WideGeom& g, int d, double X) {
  if (g.periodic[d]) return X;
  const double hi = static_cast<double>(g.n[d] - 1);
  return X < 0.0 ? 0.0 : (X > hi ? hi : X);
}

// Base cell i0 and fraction f in [0, 1] of position X along axis d (X clamped first).
MG_HD inline void axis_base(const WideGeom& g, int d, double X, long long& i0, double& f) {
  X = clamp_position(g, d, X);
  i0 = static_cast<long long>(std::floor(X));
  if (!g.periodic[d] && i0 > g.n[d] - 2) i0 = g.n[d] - 2;
  f = X - static_cast<double>(i0);
}

// Bi/trilinear interpolation of the wide-box field w at X (X[2] is the plane index in 2-D).
MG_HD inline double interp_linear(const double* w, const WideGeom& g, const double X[3]) {
  long long i0, j0;
  double fx, fy;
  axis_base(g, 0, X[0], i0, fx);
  axis_base(g, 1, X[1], j0, fy);
  auto plane = [&](long long k) {
    const double* r0 = w + g.index(i0, j0, k);
    const double* r1 = w + g.index(i0, j0 + 1, k);
    const double a = r0[0] + fx * (r0[1] - r0[0]);
    const double b = r1[0] + fx * (r1[1] - r1[0]);
    return a + fy * (b - a);
  };
  if (g.dim == 2) return plane(static_cast<long long>(X[2]));
  long long k0;
  double fz;
  axis_base(g, 2, X[2], k0, fz);
  const double a = plane(k0), b = plane(k0 + 1);
  return a + fz * (b - a);
}

// 4-point Lagrange weights of nodes -1, 0, 1, 2 at fraction f.
MG_HD inline void cubic_weights(double f, double c[4]) {
  const double fm1 = f - 1.0, fm2 = f - 2.0, fp1 = f + 1.0;
  c[0] = -f * fm1 * fm2 / 6.0;
  c[1] = fp1 * fm1 * fm2 / 2.0;
  c[2] = -fp1 * f * fm2 / 2.0;
  c[3] = fp1 * f * fm1 / 6.0;
}

// Stencil indices i0-1..i0+2 along axis d (clamped into [0, n-1] on a non-periodic axis).
MG_HD inline void cubic_indices(const WideGeom& g, int d, long long i0, long long idx[4]) {
  for (int q = 0; q < 4; ++q) {
    long long i = i0 - 1 + q;
    if (!g.periodic[d]) i = i < 0 ? 0 : (i > g.n[d] - 1 ? g.n[d] - 1 : i);
    idx[q] = i;
  }
}

// Tensor-product cubic interpolation of the wide-box field w at X.
MG_HD inline double interp_cubic(const double* w, const WideGeom& g, const double X[3]) {
  long long b[3] = {0, 0, static_cast<long long>(X[2])}, idx[3][4];
  double f[3] = {0, 0, 0}, c[3][4];
  for (int d = 0; d < g.dim; ++d) {
    axis_base(g, d, X[d], b[d], f[d]);
    cubic_indices(g, d, b[d], idx[d]);
    cubic_weights(f[d], c[d]);
  }
  auto plane = [&](long long k) {
    double sum = 0.0;
    for (int qy = 0; qy < 4; ++qy) {
      const double* row = w + g.index(g.s[0], idx[1][qy], k); // the box's row start
      const double r = c[0][0] * row[idx[0][0] - g.s[0]] + c[0][1] * row[idx[0][1] - g.s[0]] +
                       c[0][2] * row[idx[0][2] - g.s[0]] + c[0][3] * row[idx[0][3] - g.s[0]];
      sum += c[1][qy] * r;
    }
    return sum;
  };
  if (g.dim == 2) return plane(b[2]);
  double sum = 0.0;
  for (int qz = 0; qz < 4; ++qz)
    sum += c[2][qz] * plane(idx[2][qz]);
  return sum;
}

MG_HD inline double interpolate(const double* w, const WideGeom& g, const double X[3],
                                Interp interp) {
  return interp == Interp::Cubic ? interp_cubic(w, g, X) : interp_linear(w, g, X);
}

// Departure point X of the characteristic arriving at cell (i, j, k). u[d]: velocity component
// d on the wide box; dth[d] = dt / h_d. The velocity at the cell is read directly, at the
// midpoint (rk2) interpolated linearly.
MG_HD inline void backtrace(const double* const u[3], const WideGeom& g, long long i, long long j,
                            long long k, const double dth[3], Backtrace scheme, double X[3]) {
  const long long c = g.index(i, j, k);
  const double x0[3] = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
  for (int d = 0; d < 3; ++d)
    X[d] = x0[d];
  if (scheme == Backtrace::Euler) {
    for (int d = 0; d < g.dim; ++d)
      X[d] = x0[d] - u[d][c] * dth[d];
    return;
  }
  double mid[3] = {x0[0], x0[1], x0[2]};
  for (int d = 0; d < g.dim; ++d)
    mid[d] = x0[d] - 0.5 * (u[d][c] * dth[d]);
  for (int d = 0; d < g.dim; ++d)
    X[d] = x0[d] - interp_linear(u[d], g, mid) * dth[d];
}

} // namespace morphogen::advect
