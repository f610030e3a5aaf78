// Rasterisation of a polyline stroke onto a 2-D cell grid: the seed of the fast march
// (fast_marching_kernel.hpp), stable-ARD section 6 ("we rasterize its position and direction").
//
// Every cell whose centre lies within `band` of a segment (Euclidean distance in domain units,
// the minimum image on periodic axes) becomes a seed: T = its exact distance to the nearest
// segment, F = the orientation of that segment's tangent angle phi, as ncomp = 2 values
// (cos 2 phi, sin 2 phi) (an axis: phi and phi + pi alike) or ncomp = 4 values
// (cos 2 phi, sin 2 phi, cos phi, sin phi) (also the drawing direction). A cell nearer to another
// segment (of this or an earlier stroke) keeps the nearer one; exact ties keep the earlier.
// Cell (i, j) has its centre at ((i + 1/2) hx, (j + 1/2) hy); the grid is g.nx x g.ny.
// Pure kernel: no allocation, no PETSc, MPI or exceptions. Cost: each segment is cut into pieces
// no longer than two cells, and each piece visits the cells of its box widened by `band`.
#pragma once

#include "fields/fast_marching_kernel.hpp"

#include <cmath>
#include <cstdint>

namespace morphogen {

// Distance from point (px, py) to segment (ax, ay)-(bx, by).
inline double point_segment_distance(double px, double py, double ax, double ay, double bx,
                                     double by) {
  const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
  double s = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
  s = s < 0 ? 0.0 : (s > 1 ? 1.0 : s);
  const double ex = px - (ax + s * dx), ey = py - (ay + s * dy);
  return std::sqrt(ex * ex + ey * ey);
}

// Cell index along an axis of n cells, wrapped on a periodic axis; -1 outside a wall.
inline int raster_wrap(int i, int n, bool periodic) {
  if (i >= 0 && i < n) return i;
  if (!periodic) return -1;
  return ((i % n) + n) % n;
}

// Index range [lo, hi] of the cells whose centres lie within [a - band, b + band] along an axis
// of n cells of spacing h, clipped to the grid (a wall) or one period around it (periodic).
inline void raster_range(double a, double b, double band, double h, int n, int& lo, int& hi) {
  const double c = static_cast<double>(n);
  const auto clip = [c](double v) { return v < -c - 1 ? -c - 1 : (v > 2 * c + 1 ? 2 * c + 1 : v); };
  lo = static_cast<int>(clip(std::floor((a - band) / h - 0.5)));
  hi = static_cast<int>(clip(std::ceil((b + band) / h - 0.5)));
}

// A piece shifted by whole periods so that its smaller end lies in [0, L) (periodic axes).
inline double raster_shift(double a, double b, double L, bool periodic) {
  return periodic ? -L * std::floor(std::fmin(a, b) / L) : 0.0;
}

// Seed the cells near the segment piece (ax, ay)-(bx, by) of the segment with tangent angle phi.
inline void raster_piece(const FmmGrid& g, double band, double ax, double ay, double bx, double by,
                         double phi, int ncomp, double* T, std::uint8_t* state, double* F) {
  const double sx = raster_shift(ax, bx, g.nx * g.hx, g.periodic_x);
  const double sy = raster_shift(ay, by, g.ny * g.hy, g.periodic_y);
  ax += sx, bx += sx, ay += sy, by += sy;
  int i0, i1, j0, j1;
  raster_range(std::fmin(ax, bx), std::fmax(ax, bx), band, g.hx, g.nx, i0, i1);
  raster_range(std::fmin(ay, by), std::fmax(ay, by), band, g.hy, g.ny, j0, j1);
  const double f[4] = {std::cos(2 * phi), std::sin(2 * phi), std::cos(phi), std::sin(phi)};
  for (int j = j0; j <= j1; ++j) {
    const int jw = raster_wrap(j, g.ny, g.periodic_y);
    if (jw < 0) continue;
    for (int i = i0; i <= i1; ++i) {
      const int iw = raster_wrap(i, g.nx, g.periodic_x);
      if (iw < 0) continue;
      const double d = point_segment_distance((i + 0.5) * g.hx, (j + 0.5) * g.hy, ax, ay, bx, by);
      const int c = iw + g.nx * jw;
      if (d > band || (state[c] == kFmmKnown && !(d < T[c]))) continue;
      T[c] = d;
      state[c] = kFmmKnown;
      for (int k = 0; k < ncomp; ++k)
        F[ncomp * c + k] = f[k];
    }
  }
}

// Seed the cells near the polyline xy[0..2 npts) (x0, y0, x1, y1, ...; domain units; segments
// of zero length are skipped). On periodic axes a stroke may leave the domain and wraps.
inline void rasterise_polyline(const FmmGrid& g, double band, const double* xy, int npts, int ncomp,
                               double* T, std::uint8_t* state, double* F) {
  const double piece = 2.0 * std::fmin(g.hx, g.hy);
  for (int p = 0; p + 1 < npts; ++p) {
    const double ax = xy[2 * p], ay = xy[2 * p + 1], bx = xy[2 * p + 2], by = xy[2 * p + 3];
    const double len = std::hypot(bx - ax, by - ay);
    if (!(len > 0)) continue;
    const double phi = std::atan2(by - ay, bx - ax);
    const int m = static_cast<int>(std::ceil(len / piece));
    for (int q = 0; q < m; ++q) {
      const double s0 = static_cast<double>(q) / m, s1 = static_cast<double>(q + 1) / m;
      raster_piece(g, band, ax + s0 * (bx - ax), ay + s0 * (by - ay), ax + s1 * (bx - ax),
                   ay + s1 * (by - ay), phi, ncomp, T, state, F);
    }
  }
}

} // namespace morphogen
