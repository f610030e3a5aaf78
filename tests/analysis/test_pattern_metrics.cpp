// Serial tests for src/analysis/pattern_metrics: synthetic fields with known truth.
//
// Hexagonal spots (64 maxima, wavelength 16 cells, on a 128 x 148 torus) and stripes: see
// synthetic_fields.hpp; discs below. Tolerances: wavelength within 3 %, spot counts exact.
#include "analysis/pattern_metrics.hpp"
#include "synthetic_fields.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

using namespace morphogen::analysis;
using namespace morphogen::testing;

namespace {

// 1 inside the disc of radius r about (cx, cy) (minimum image: the disc wraps), else 0; the
// shape is analysed as periodic or not.
Field disc_field(int n, double cx, double cy, double r, bool periodic) {
  Field f = make(n, n);
  f.shape.periodic_x = f.shape.periodic_y = periodic;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double dx = i + 0.5 - cx, dy = j + 0.5 - cy;
      dx -= n * std::round(dx / n);
      dy -= n * std::round(dy / n);
      f.at(i, j) = (dx * dx + dy * dy <= r * r) ? 1.0 : 0.0;
    }
  return f;
}

} // namespace

TEST(PatternMetrics, HexagonalSpotsCountAndWavelength) {
  Field f = hexagonal();
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  ASSERT_TRUE(m.finite);
  EXPECT_NEAR(m.wavelength_cells, 16.0, 0.03 * 16.0);
  EXPECT_NEAR(m.wavelength, 16.0, 0.03 * 16.0);
  EXPECT_EQ(m.high.spots, 64);
  EXPECT_EQ(m.high.components, 64);
  EXPECT_DOUBLE_EQ(m.high.spot_area_fraction, 1.0);
  EXPECT_LT(m.high.median_elongation, 1.2);
  EXPECT_GT(m.high.median_fill, 0.9);
  EXPECT_EQ(m.low.components, 1); // the connected background
  EXPECT_EQ(m.low.networks, 1);
  EXPECT_EQ(m.euler, 64);
  EXPECT_LT(m.spectral_anisotropy, 0.05); // six-fold symmetric
  EXPECT_GT(m.peak_power_fraction, 0.9);  // smooth: all power in the fundamental ring
  EXPECT_LT(m.gridscale_power_fraction, 1e-6);
  // Spot size: the region f > 0.75 of each unit cell; 64 spots tile a fraction of the torus.
  EXPECT_NEAR(m.high.spot_area_cells * 64, m.high.area_fraction * 128 * 148, 1e-6);
}

TEST(PatternMetrics, ThresholdedHexagonalSpotsAndPhysicalUnits) {
  Field f = hexagonal(0.5); // same cells, half the spacing: wavelength 8 length units
  for (double& v : f.u)
    v = v > 0.5 ? 1.0 : 0.0;
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_NEAR(m.wavelength, 8.0, 0.03 * 8.0);
  EXPECT_NEAR(m.wavelength_cells, 16.0, 0.03 * 16.0);
  EXPECT_EQ(m.high.spots, 64);
  EXPECT_NEAR(m.high.spot_area, m.high.spot_area_cells * 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(m.threshold, 0.5);
}

TEST(PatternMetrics, NegatedHexagonalIsHoles) {
  Field f = hexagonal();
  for (double& v : f.u)
    v = -v;
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_NEAR(m.wavelength_cells, 16.0, 0.03 * 16.0);
  EXPECT_EQ(m.low.spots, 64);
  EXPECT_EQ(m.high.components, 1);
  EXPECT_EQ(m.high.networks, 1);
  EXPECT_EQ(m.euler, -64);
}

TEST(PatternMetrics, ParallelStripes) {
  Field f = stripes(128, 8, 0); // wave vector along x: 8 vertical stripes, wavelength 16
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_NEAR(m.wavelength_cells, 16.0, 0.03 * 16.0);
  EXPECT_EQ(m.high.components, 8);
  EXPECT_EQ(m.high.wrapping, 8);
  EXPECT_EQ(m.high.networks, 0);
  EXPECT_EQ(m.low.wrapping, 8);
  EXPECT_EQ(m.high.spots, 0);
  EXPECT_TRUE(std::isinf(m.high.median_elongation));
  EXPECT_GT(m.spectral_anisotropy, 0.99);
  EXPECT_NEAR(m.spectral_angle, 0.0, 1e-6); // wave vector along x
  EXPECT_GT(m.coherence, 0.95);
  EXPECT_EQ(m.euler, 0);
}

TEST(PatternMetrics, ObliqueStripesCommensurateWithTorus) {
  Field f = stripes(128, 3, 4); // |k| = 5 cycles per 128: wavelength 25.6 cells
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_NEAR(m.wavelength_cells, 25.6, 0.03 * 25.6);
  EXPECT_GE(m.high.wrapping, 1);
  EXPECT_EQ(m.high.spots, 0);
  EXPECT_EQ(m.low.spots, 0);
  EXPECT_GT(m.spectral_anisotropy, 0.99);
  EXPECT_NEAR(m.spectral_angle, std::atan2(4.0, 3.0), 1e-6);
  EXPECT_GT(m.coherence, 0.95);
  EXPECT_EQ(m.euler, 0);
}

TEST(PatternMetrics, NonPeriodicAxesAreWindowed) {
  // Wavelength 15.3 cells, not commensurate with the 128-cell box: periodic analysis would see
  // a jump at the edges; the Hann window keeps the peak within 3 % and the orientation exact.
  Field f = make(128, 128);
  f.shape.periodic_x = f.shape.periodic_y = false;
  for (int j = 0; j < 128; ++j)
    for (int i = 0; i < 128; ++i)
      f.at(i, j) = 2.0 + std::cos(2 * kPi * (i + 0.5) / 15.3);
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_NEAR(m.wavelength_cells, 15.3, 0.03 * 15.3);
  EXPECT_GT(m.spectral_anisotropy, 0.95);
  EXPECT_EQ(m.high.wrapping, 0); // no wrap across closed edges
  EXPECT_EQ(m.high.spots, 0);    // long bars: elongated
}

TEST(PatternMetrics, SpotSplitAcrossTheBoundaryCountsOnce) {
  // A disc centred on the corner of a 64^2 torus is cut into four quarters by the edges.
  Field f = disc_field(64, 0.0, 0.0, 6.0, true);
  PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_EQ(m.high.components, 1);
  EXPECT_EQ(m.high.spots, 1);
  EXPECT_LT(m.high.median_elongation, 1.1);
  EXPECT_NEAR(m.high.spot_area_cells, kPi * 36, 0.05 * kPi * 36);
  EXPECT_EQ(m.euler, 1);
  // Centroid of the unwrapped disc: the corner itself (or, wrapped, the opposite corner).
  std::vector<unsigned char> mask(f.u.size());
  for (std::size_t c = 0; c < mask.size(); ++c)
    mask[c] = f.u[c] > 0.5;
  const auto comps = label_components(mask.data(), f.shape, 4);
  ASSERT_EQ(comps.size(), 1u);
  EXPECT_NEAR(std::remainder(comps[0].cx, 64.0), 0.0, 1e-9);
  EXPECT_NEAR(std::remainder(comps[0].cy, 64.0), 0.0, 1e-9);
  EXPECT_EQ(comps[0].winding_rank, 0);

  // A disc across the x edge only.
  f = disc_field(64, 0.0, 30.0, 6.0, true);
  m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_EQ(m.high.spots, 1);

  // The same wrapped disc analysed in a closed box is four separate quarter discs.
  f = disc_field(64, 0.0, 0.0, 6.0, false);
  m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_EQ(m.high.components, 4);
}

TEST(PatternMetrics, WindingRanks) {
  const FieldShape2D torus{32, 32, 1, 1, true, true};
  std::vector<unsigned char> band(32 * 32, 0), cross(32 * 32, 0), diagonal(32 * 32, 0);
  for (int i = 0; i < 32; ++i) {
    for (int w = 0; w < 3; ++w) {
      band[i + 32 * (10 + w)] = 1;
      cross[i + 32 * (10 + w)] = 1;
      cross[(20 + w) + 32 * i] = 1;
    }
    diagonal[i + 32 * i] = 1; // 8-connected only, winds along (1, 1)
  }
  auto b = label_components(band.data(), torus, 4);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].winding_rank, 1);
  EXPECT_TRUE(std::isinf(b[0].elongation));
  EXPECT_FALSE(b[0].spot);
  auto c = label_components(cross.data(), torus, 4);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].winding_rank, 2);
  auto d8 = label_components(diagonal.data(), torus, 8);
  ASSERT_EQ(d8.size(), 1u);
  EXPECT_EQ(d8[0].winding_rank, 1);
  auto d4 = label_components(diagonal.data(), torus, 4);
  EXPECT_EQ(d4.size(), 32u); // single cells: specks
  EXPECT_TRUE(d4[0].speck);
  EXPECT_EQ(euler_characteristic_4(band.data(), torus), 0);
  EXPECT_EQ(euler_characteristic_4(cross.data(), torus), -1); // torus minus a disc
  EXPECT_EQ(euler_characteristic_4(diagonal.data(), torus), 32);
}

TEST(PatternMetrics, ElongationAndFillOfSimpleShapes) {
  const FieldShape2D box{64, 64, 1, 1, false, false};
  std::vector<unsigned char> bar(64 * 64, 0), ring(64 * 64, 0);
  for (int j = 30; j < 34; ++j)
    for (int i = 10; i < 50; ++i)
      bar[i + 64 * j] = 1; // 40 x 4: axis ratio 10
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      const double r = std::hypot(i + 0.5 - 32, j + 0.5 - 32);
      ring[i + 64 * j] = (r >= 12 && r <= 15) ? 1 : 0;
    }
  auto b = label_components(bar.data(), box, 4);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].elongation, 10.0, 0.01);
  EXPECT_NEAR(b[0].fill, 40.0 * 4 / (4 * kPi * 40 * 4 / 12), 1e-9); // 3 / pi
  EXPECT_FALSE(b[0].spot);
  auto r = label_components(ring.data(), box, 4);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_LT(r[0].elongation, 1.05);
  EXPECT_LT(r[0].fill, 0.3); // round, but hollow: not a spot
  EXPECT_FALSE(r[0].spot);
}

TEST(PatternMetrics, UniformAndNonFiniteFields) {
  Field f = make(32, 32);
  for (double& v : f.u)
    v = 3.0;
  PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_TRUE(m.finite);
  EXPECT_EQ(m.range_rel, 0.0);
  EXPECT_EQ(m.wavelength, 0.0);
  EXPECT_EQ(m.high.components, 0);
  EXPECT_EQ(m.low.components, 1);
  EXPECT_DOUBLE_EQ(m.mean, 3.0);
  EXPECT_EQ(m.stddev, 0.0);

  f.at(5, 7) = std::numeric_limits<double>::quiet_NaN();
  f.at(6, 7) = std::numeric_limits<double>::infinity();
  m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_FALSE(m.finite);
  EXPECT_EQ(m.nonfinite, 2);
}

TEST(PatternMetrics, Statistics) {
  Field f = make(10, 10);
  for (int c = 0; c < 100; ++c)
    f.u[c] = c; // 0 .. 99
  const PatternMetrics m = compute_pattern_metrics(f.u.data(), f.shape);
  EXPECT_DOUBLE_EQ(m.mean, 49.5);
  EXPECT_DOUBLE_EQ(m.p5, 4.0);   // floor(0.05 * 99)
  EXPECT_DOUBLE_EQ(m.p95, 94.0); // floor(0.95 * 99)
  EXPECT_NEAR(m.stddev, std::sqrt((100.0 * 100 - 1) / 12), 1e-12);
  EXPECT_NEAR(m.contrast, 90.0 / 49.5, 1e-12);
}

TEST(PatternMetrics, RejectsBadShapes) {
  const double u[4] = {0, 1, 2, 3};
  EXPECT_THROW(compute_pattern_metrics(u, FieldShape2D{0, 4, 1, 1, true, true}),
               std::invalid_argument);
  EXPECT_THROW(compute_pattern_metrics(u, FieldShape2D{2, 2, 0, 1, true, true}),
               std::invalid_argument);
  const unsigned char mask[4] = {1, 0, 0, 1};
  EXPECT_THROW(label_components(mask, FieldShape2D{2, 2, 1, 1, true, true}, 6),
               std::invalid_argument);
}
