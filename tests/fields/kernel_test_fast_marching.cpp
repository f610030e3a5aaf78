// Fast marching with extension velocities and stroke rasterisation
// (fields/fast_marching_kernel.hpp, fields/strokes_raster_kernel.hpp), against exact distances and
// tangent angles. Built without PETSc or MPI.
#include "fields/fast_marching_kernel.hpp"
#include "fields/strokes_raster_kernel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

using namespace morphogen;

namespace {

struct March {
  FmmGrid g;
  int ncomp;
  std::vector<double> T, F;
  std::vector<std::uint8_t> state;
  March(FmmGrid grid, int nc)
      : g(grid), ncomp(nc), T(size(), INFINITY), F(size() * nc, 0.0), state(size(), kFmmFar) {}
  size_t size() const { return static_cast<size_t>(g.nx) * g.ny; }
  double band() const { return std::fmax(g.hx, g.hy); }
  void polyline(const std::vector<double>& xy) {
    rasterise_polyline(g, band(), xy.data(), static_cast<int>(xy.size() / 2), ncomp, T.data(),
                       state.data(), F.data());
  }
  void run() {
    std::vector<int> heap(size()), pos(size());
    std::vector<double> key(size());
    fast_marching(g, T.data(), state.data(), F.data(), ncomp, heap.data(), key.data(), pos.data());
  }
  double x(int i) const { return (i + 0.5) * g.hx; }
  double y(int j) const { return (j + 0.5) * g.hy; }
  double axis(int c) const { return 0.5 * std::atan2(F[ncomp * c + 1], F[ncomp * c]); }
};

// Difference of two axis angles modulo pi, in [0, pi/2].
double axis_difference(double a, double b) {
  double d = std::fmod(std::abs(a - b), M_PI);
  return d > M_PI / 2 ? M_PI - d : d;
}

} // namespace

// A single stroke point at the centre of a 128 x 96 grid (hx = 1, hy = 0.75). First-order fast
// marching overestimates the distance most along the diagonals (the point-source singularity);
// measured here: max T - r = 1.12 h over the grid (r up to ~80 h). Bound asserted:
// T - r <= 0.05 r + 0.5 h, and T >= r - 1e-12 (the upwind scheme never underestimates).
TEST(FastMarching, SinglePointDistanceIsEuclideanToFirstOrder) {
  March m({128, 96, 1.0, 0.75, false, false}, 2);
  const double px = 64.3, py = 35.9;
  raster_piece(m.g, m.band(), px, py, px, py, 0.0, m.ncomp, m.T.data(), m.state.data(), m.F.data());
  m.run();
  double worst = 0, worst_rel = 0;
  for (int j = 0; j < m.g.ny; ++j)
    for (int i = 0; i < m.g.nx; ++i) {
      const double r = std::hypot(m.x(i) - px, m.y(j) - py), t = m.T[i + m.g.nx * j];
      ASSERT_GE(t, r - 1e-12) << i << "," << j;
      ASSERT_LE(t - r, 0.05 * r + 0.5 * m.g.hx) << i << "," << j;
      worst = std::fmax(worst, t - r);
      worst_rel = std::fmax(worst_rel, (t - r) / std::fmax(r, 1.0));
    }
  std::printf("single point: max |T - r| = %.3f h, max relative %.4f\n", worst, worst_rel);
  EXPECT_GT(worst, 0.0); // first order: not exact (the test can see the scheme's error)
}

// On a periodic axis the distance wraps: a point near x = 0 is near the cells at x = L.
TEST(FastMarching, PeriodicDistanceWraps) {
  March m({64, 32, 1.0, 1.0, true, false}, 2);
  raster_piece(m.g, m.band(), 0.2, 16.0, 0.2, 16.0, 0.0, 2, m.T.data(), m.state.data(), m.F.data());
  m.run();
  EXPECT_EQ(m.state[63 + 64 * 15], kFmmKnown);
  EXPECT_NEAR(m.T[63 + 64 * 15], std::hypot(64.2 - 63.5, 0.5), 1e-12); // a seed: exact
  EXPECT_NEAR(m.T[56 + 64 * 15], std::hypot(64.2 - 56.5, 0.5), 0.3);   // across the wrap, not 55.8
}

// A straight stroke at 30 degrees: the extended orientation is the stroke's at every cell (to
// round-off), and the distance is the exact one within first-order error (measured max 0.41 h,
// at the walls where the front leaves the stroke's end; asserted 0.05 d + 0.5 h).
TEST(FastMarching, StraightStrokeOrientationIsConstant) {
  March m({96, 80, 1.0, 1.0, false, false}, 4);
  const double a = M_PI / 6, cx = 40.2, cy = 41.7;
  m.polyline({cx - 150 * std::cos(a), cy - 150 * std::sin(a), cx + 150 * std::cos(a),
              cy + 150 * std::sin(a)});
  m.run();
  for (size_t c = 0; c < m.size(); ++c) {
    ASSERT_NEAR(m.axis(static_cast<int>(c)), a, 1e-12) << c;
    ASSERT_NEAR(std::atan2(m.F[4 * c + 3], m.F[4 * c + 2]), a, 1e-12) << c; // directed
  }
  // The reference: the distance to the part of the line inside the domain (the rasterised part;
  // where the nearest point of the whole line lies outside, the march cannot see it).
  const double t0 = std::fmax(-cx / std::cos(a), -cy / std::sin(a));
  const double t1 = std::fmin((96 - cx) / std::cos(a), (80 - cy) / std::sin(a));
  const double ax = cx + t0 * std::cos(a), ay = cy + t0 * std::sin(a);
  const double bx = cx + t1 * std::cos(a), by = cy + t1 * std::sin(a);
  double worst = 0;
  for (size_t c = 0; c < m.size(); ++c) {
    const int i = static_cast<int>(c) % m.g.nx, j = static_cast<int>(c) / m.g.nx;
    const double d = point_segment_distance(m.x(i), m.y(j), ax, ay, bx, by);
    ASSERT_NEAR(m.T[c], d, 0.05 * d + 0.5) << i << "," << j;
    worst = std::fmax(worst, std::abs(m.T[c] - d));
  }
  std::printf("straight stroke: max |T - d| = %.3f h\n", worst);
}

// A circle stroke of radius 30 (drawn counter-clockwise, 256 chords) about the centre of a
// 128 x 128 grid: at every cell farther than 10 cells from the centre the extended axis is the
// tangent at the nearest circle point, angle(x - c) + pi/2 mod pi, and the directed angle is
// that tangent's direction mod 2 pi. Outside the circle: measured max error 0.014 rad (the
// chords turn by 2 pi / 256 = 0.025 rad), asserted 0.02. Inside, where the characteristics
// converge on the centre and the grid resolves angles of ~h/r: measured 0.02 + 0.44 h/r,
// asserted 0.02 + 0.8 h/r. Distances within 0.05 d + 0.5 h.
TEST(FastMarching, CircleStrokeGivesTheTangent) {
  March m({128, 128, 1.0, 1.0, false, false}, 4);
  const double cx = 63.7, cy = 64.2, R = 30;
  std::vector<double> xy;
  for (int k = 0; k <= 256; ++k) {
    const double s = 2 * M_PI * k / 256;
    xy.push_back(cx + R * std::cos(s));
    xy.push_back(cy + R * std::sin(s));
  }
  m.polyline(xy);
  m.run();
  double worst_in = 0, worst_out = 0;
  for (int j = 0; j < m.g.ny; ++j)
    for (int i = 0; i < m.g.nx; ++i) {
      const double dx = m.x(i) - cx, dy = m.y(j) - cy, r = std::hypot(dx, dy);
      if (r < 10) continue;
      const int c = i + m.g.nx * j;
      const double tangent = std::atan2(dy, dx) + M_PI / 2;
      const double e = axis_difference(m.axis(c), tangent);
      const double ed =
          std::abs(std::remainder(std::atan2(m.F[4 * c + 3], m.F[4 * c + 2]) - tangent, 2 * M_PI));
      const double tol = r < R ? 0.02 + 0.8 / r : 0.02; // inside: the grid resolves angle ~h/r
      ASSERT_LE(e, tol) << i << "," << j;
      ASSERT_LE(ed, tol) << i << "," << j;
      if (r < R) worst_in = std::fmax(worst_in, (std::fmax(e, ed) - 0.02) * r);
      if (r >= R) worst_out = std::fmax(worst_out, std::fmax(e, ed));
      ASSERT_NEAR(m.T[c], std::abs(r - R), 0.05 * std::abs(r - R) + 0.5) << i << "," << j;
    }
  std::printf("circle: tangent error inside <= 0.02 + %.3f h / r (r >= 10), outside %.4f rad\n",
              worst_in, worst_out);
}

// Rasterisation alone: the seeds are the cells within the band, at their exact distance.
TEST(StrokeRaster, SeedsAreTheCellsWithinTheBand) {
  March m({32, 32, 0.5, 0.5, false, false}, 2);
  m.polyline({2.0, 3.1, 12.0, 3.1});
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 32; ++i) {
      const int c = i + 32 * j;
      const double d = point_segment_distance(m.x(i), m.y(j), 2.0, 3.1, 12.0, 3.1);
      EXPECT_EQ(m.state[c] == kFmmKnown, d <= 0.5) << i << "," << j;
      if (m.state[c] == kFmmKnown) {
        EXPECT_DOUBLE_EQ(m.T[c], d);
      }
    }
}

// A stroke far outside a walled domain seeds nothing (and reads no memory out of range).
TEST(StrokeRaster, StrokeOutsideTheDomainSeedsNothing) {
  March m({16, 16, 1.0, 1.0, false, false}, 2);
  m.polyline({-1e30, 5.0, -1e29, 7.0, 1e12, -1e12});
  for (auto s : m.state)
    EXPECT_EQ(s, kFmmFar);
}
