// Laplacian stencils: exact on quadratics (second order), spectral radius at the Nyquist
// corner, and the explicit stability bound dt <= h^2 / (2 dim D) for 5/7-point stencils.
#include "integrators/explicit_integrator.hpp"
#include "operators/stencil.hpp"

#include <gtest/gtest.h>

using namespace morphogen;

namespace {

// Evaluate stencil on f at a point (x0,y0,z0) with spacings h.
template <class F> double lap_at(const Stencil& s, const double* h, F f) {
  const double x0 = 0.37, y0 = -1.3, z0 = 2.1;
  return s.apply(
      [&](int dx, int dy, int dz) { return f(x0 + dx * h[0], y0 + dy * h[1], z0 + dz * h[2]); });
}

} // namespace

TEST(Stencil, FivePointExactOnQuadratics) {
  const double h[3] = {0.25, 0.4, 1.0};
  Stencil s;
  ASSERT_TRUE(make_stencil("5pt", 2, h, s));
  EXPECT_EQ(s.nterms, 5);
  // lap(3x^2 - 2y^2 + 5xy + 7x - y + 4) = 6 - 4 = 2
  EXPECT_NEAR(lap_at(s, h,
                     [](double x, double y, double) {
                       return 3 * x * x - 2 * y * y + 5 * x * y + 7 * x - y + 4;
                     }),
              2.0, 1e-11);
  EXPECT_NEAR(lap_at(s, h, [](double, double, double) { return 1.0; }), 0.0, 1e-12);
}

TEST(Stencil, NinePointIsotropicExactOnQuadratics) {
  const double h[3] = {0.5, 0.5, 1.0};
  Stencil s;
  ASSERT_TRUE(make_stencil("9pt", 2, h, s));
  EXPECT_EQ(s.nterms, 9);
  EXPECT_NEAR(
      lap_at(s, h, [](double x, double y, double) { return x * x + y * y + 3 * x * y - x; }), 4.0,
      1e-11);
  // Garrity's operator: -u + 0.2 (edges) + 0.05 (corners) = 0.3 h^2 * lap.
  const double hh[3] = {1, 1, 1};
  ASSERT_TRUE(make_stencil("9pt", 2, hh, s));
  EXPECT_NEAR(s.w[0] * 0.3, -1.0, 1e-15);
  EXPECT_NEAR(s.w[1] * 0.3, 0.2, 1e-15);
  EXPECT_NEAR(s.w[5] * 0.3, 0.05, 1e-15);
  // Unequal spacing is refused.
  const double hu[3] = {0.5, 0.25, 1};
  EXPECT_FALSE(make_stencil("9pt", 2, hu, s));
}

TEST(Stencil, SevenPointExactOnQuadratics) {
  const double h[3] = {0.5, 0.25, 0.2};
  Stencil s;
  ASSERT_TRUE(make_stencil("7pt", 3, h, s));
  EXPECT_EQ(s.nterms, 7);
  EXPECT_NEAR(lap_at(s, h,
                     [](double x, double y, double z) {
                       return x * x + 2 * y * y - 0.5 * z * z + x * y * z + y * z;
                     }),
              2 + 4 - 1, 1e-10);
}

TEST(Stencil, UnknownOrWrongDimensionRefused) {
  const double h[3] = {1, 1, 1};
  Stencil s;
  EXPECT_FALSE(make_stencil("7pt", 2, h, s));
  EXPECT_FALSE(make_stencil("5pt", 3, h, s));
  EXPECT_FALSE(make_stencil("13pt", 2, h, s));
}

TEST(Stencil, SpectralRadiusAndStableDt) {
  const double h[3] = {0.5, 0.5, 0.5};
  Stencil s5, s9, s7;
  ASSERT_TRUE(make_stencil("5pt", 2, h, s5));
  ASSERT_TRUE(make_stencil("9pt", 2, h, s9));
  ASSERT_TRUE(make_stencil("7pt", 3, h, s7));
  EXPECT_NEAR(s5.spectral_radius(), 8.0 / 0.25, 1e-12);
  EXPECT_NEAR(s9.spectral_radius(), 32.0 / (6.0 * 0.25), 1e-12);
  EXPECT_NEAR(s7.spectral_radius(), 12.0 / 0.25, 1e-12);
  // dt <= h^2 / (2 dim D_max)
  EXPECT_NEAR(ExplicitIntegrator::stable_dt(s5, {0.1, 0.4}), 0.25 / (4 * 0.4), 1e-15);
  EXPECT_NEAR(ExplicitIntegrator::stable_dt(s7, {0.4}), 0.25 / (6 * 0.4), 1e-15);
  EXPECT_TRUE(std::isinf(ExplicitIntegrator::stable_dt(s5, {0.0, 0.0})));
}
