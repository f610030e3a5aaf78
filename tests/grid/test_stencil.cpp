// Laplacian stencils: exact on quadratics (second order), spectral radius at the Nyquist
// corner, and the explicit stability bound dt <= h^2 / (2 dim D) for 5/7-point stencils.
#include "grid/stencil.hpp"
#include "integrators/explicit_integrator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

TEST(Stencil, RowFormGroupsTermsByRow) {
  const double h[3] = {0.5, 0.25, 0.2};
  const double hs[3] = {0.5, 0.5, 0.5};
  Stencil s5, s7, s9;
  ASSERT_TRUE(make_stencil("5pt", 2, h, s5));
  ASSERT_TRUE(make_stencil("7pt", 3, h, s7));
  ASSERT_TRUE(make_stencil("9pt", 2, hs, s9));
  for (const Stencil* s : {&s5, &s7, &s9}) {
    RowStencil r;
    ASSERT_TRUE(to_rows(*s, r));
    EXPECT_EQ(r.nrows, s == &s7 ? 5 : 3);
    EXPECT_EQ(r.box, s == &s9);
    EXPECT_EQ(r.off[0][0], 0);
    EXPECT_EQ(r.off[0][1], 0);
    // The row form applied to a quadratic equals the stencil applied to it.
    auto f = [](double x, double y, double z) { return x * x - 3 * y * y + 2 * z * z + x * y; };
    double rows_sum = 0;
    for (int q = 0; q < r.nrows; ++q)
      for (int dx = -1; dx <= 1; ++dx)
        rows_sum += r.w[3 * q + dx + 1] * f(0.1 + dx * (s == &s9 ? hs : h)[0],
                                            0.2 + r.off[q][0] * (s == &s9 ? hs : h)[1],
                                            0.3 + r.off[q][1] * (s == &s9 ? hs : h)[2]);
    const double* hh = s == &s9 ? hs : h;
    const double direct = s->apply([&](int dx, int dy, int dz) {
      return f(0.1 + dx * hh[0], 0.2 + dy * hh[1], 0.3 + dz * hh[2]);
    });
    EXPECT_NEAR(rows_sum, direct, 1e-10);
  }
}

// Symbol of a stencil at wave vector k (h = 1): sum_t w_t cos(k . off_t).
double symbol(const Stencil& s, const double* k) {
  double v = 0;
  for (int t = 0; t < s.nterms; ++t)
    v += s.w[t] * std::cos(k[0] * s.off[t][0] + k[1] * s.off[t][1] + k[2] * s.off[t][2]);
  return v;
}

TEST(Stencil, ThreeDBoxStencilsIsotropicSecondOrder) {
  const double h[3] = {0.3, 0.3, 0.3}, h1[3] = {1, 1, 1};
  for (const char* name : {"19pt", "27pt"}) {
    Stencil s;
    ASSERT_TRUE(make_stencil(name, 3, h, s)) << name;
    EXPECT_EQ(s.nterms, std::string(name) == "19pt" ? 19 : 27);
    EXPECT_NEAR(lap_at(s, h,
                       [](double x, double y, double z) {
                         return x * x + 2 * y * y - 0.5 * z * z + x * y * z + 3 * y * z - x;
                       }),
                2 + 4 - 1, 1e-10)
        << name;
    // Symbol -|k|^2 + |k|^4 / 12 + O(k^6) in every direction (isotropic leading error), where
    // the 7-point stencil's k^4 term is (kx^4 + ky^4 + kz^4) / 12: 1/12 along an axis, 1/36
    // along the diagonal.
    Stencil s1;
    ASSERT_TRUE(make_stencil(name, 3, h1, s1));
    const double eps = 0.02, r3 = 1.0 / std::sqrt(3.0);
    const double axis[3] = {eps, 0, 0}, diag[3] = {eps * r3, eps * r3, eps * r3};
    for (const double* k : {axis, diag})
      EXPECT_NEAR((symbol(s1, k) + eps * eps) / std::pow(eps, 4), 1.0 / 12.0, 1e-4) << name;
    // Spectral radius: 16/3 (19pt, at (pi, pi, 0) and permutations), 184/30 (27pt, at
    // (pi, pi, pi)), over h^2.
    EXPECT_NEAR(s1.spectral_radius(), std::string(name) == "19pt" ? 16.0 / 3.0 : 184.0 / 30.0,
                1e-12);
    RowStencil r;
    ASSERT_TRUE(to_rows(s, r));
    EXPECT_EQ(r.nrows, 9);
    EXPECT_TRUE(r.box);
    // Unequal spacing and 2-D are refused.
    const double hu[3] = {0.3, 0.3, 0.2};
    EXPECT_FALSE(make_stencil(name, 3, hu, s));
    EXPECT_FALSE(make_stencil(name, 2, h, s));
  }
}

// The weight-class form of the 3-D box stencils (the explicit kernel's fast path): class
// weights equal to the published ones (Patra & Karttunen: 19pt {-24, 2, 1, 0} / 6h^2, 27pt
// {-128, 14, 3, 1} / 30h^2), perm listing the centre, the 4 face rows and the 4 corner rows,
// and a stencil whose taps differ within a class (or that is not a 9-row box) refused.
TEST(Stencil, BoxClassesOfTheIsotropicBoxStencils) {
  const double h[3] = {0.5, 0.5, 0.5};
  const double s2 = 1.0 / (h[0] * h[0]);
  for (const char* name : {"19pt", "27pt"}) {
    const bool full = std::string(name) == "27pt";
    const double expect[4] = {full ? -128.0 / 30 : -24.0 / 6, full ? 14.0 / 30 : 2.0 / 6,
                              full ? 3.0 / 30 : 1.0 / 6, full ? 1.0 / 30 : 0.0};
    Stencil s;
    ASSERT_TRUE(make_stencil(name, 3, h, s));
    RowStencil r;
    ASSERT_TRUE(to_rows(s, r));
    BoxClasses c;
    ASSERT_TRUE(box_classes(r, c)) << name;
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(c.w[k], expect[k] * s2, 1e-12 * s2) << name << " class " << k;
    EXPECT_EQ(c.perm[0], 0);
    int seen = 0;
    for (int q = 0; q < 9; ++q) {
      const int yz = (r.off[c.perm[q]][0] != 0) + (r.off[c.perm[q]][1] != 0);
      EXPECT_EQ(yz, q == 0 ? 0 : q < 5 ? 1 : 2) << name << " position " << q;
      seen |= 1 << c.perm[q];
    }
    EXPECT_EQ(seen, 0x1ff) << "perm is a permutation of the 9 rows";
    // The class form reproduces every tap of the row form.
    for (int q = 0; q < 9; ++q)
      for (int dx = -1; dx <= 1; ++dx) {
        const int k = (r.off[q][0] != 0) + (r.off[q][1] != 0) + (dx != 0);
        EXPECT_EQ(r.w[3 * q + dx + 1], c.w[k]) << name;
      }
    // One edge tap changed: no longer one weight per class.
    RowStencil bad = r;
    bad.w[3 * c.perm[1]] *= 1.5;
    EXPECT_FALSE(box_classes(bad, c));
    RowStencil dup = r; // a row repeated (the 3x3 rows not all present)
    dup.off[8] = dup.off[7];
    EXPECT_FALSE(box_classes(dup, c));
  }
  Stencil s5, s7;
  RowStencil r5, r7;
  BoxClasses c;
  ASSERT_TRUE(make_stencil("5pt", 2, h, s5));
  ASSERT_TRUE(make_stencil("7pt", 3, h, s7));
  ASSERT_TRUE(to_rows(s5, r5));
  ASSERT_TRUE(to_rows(s7, r7));
  EXPECT_FALSE(box_classes(r5, c)) << "star stencils have no class form";
  EXPECT_FALSE(box_classes(r7, c));
}

// 2-D 9pt: (4 (N+S+E+W) + diagonals - 20 u) / (6 h^2) as centre, face and edge (the diagonals)
// classes, no corner class; the rows in class order; a changed tap or row refused.
TEST(Stencil, BoxClassesOfThe2D9ptStencil) {
  const double h[3] = {0.5, 0.5, 0.5};
  const double s2 = 1.0 / (h[0] * h[0]);
  Stencil s;
  ASSERT_TRUE(make_stencil("9pt", 2, h, s));
  RowStencil r;
  ASSERT_TRUE(to_rows(s, r));
  BoxClasses c;
  ASSERT_TRUE(box_classes(r, c));
  const double expect[4] = {-20.0 / 6, 4.0 / 6, 1.0 / 6, 0.0};
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(c.w[k], expect[k] * s2, 1e-12 * s2) << "class " << k;
  EXPECT_EQ(c.perm[0], 0);
  EXPECT_EQ(std::abs(r.off[c.perm[1]][0]) + std::abs(r.off[c.perm[2]][0]), 2);
  EXPECT_NE(c.perm[1], c.perm[2]);
  for (int q = 0; q < 3; ++q)
    for (int dx = -1; dx <= 1; ++dx)
      EXPECT_EQ(r.w[3 * q + dx + 1], c.w[(r.off[q][0] != 0) + (dx != 0)]);
  RowStencil ordered = r;
  BoxClasses c2;
  ASSERT_TRUE(to_class_order(ordered, c2));
  for (int q = 0; q < 3; ++q) {
    EXPECT_EQ(ordered.off[q], r.off[c.perm[q]]);
    for (int t = 0; t < 3; ++t)
      EXPECT_EQ(ordered.w[3 * q + t], r.w[3 * c.perm[q] + t]);
  }
  RowStencil bad = r; // a face tap changed (as for hx != hy)
  bad.w[3 * c.perm[1] + 1] *= 1.5;
  EXPECT_FALSE(box_classes(bad, c2));
  RowStencil dup = r; // a row repeated
  dup.off[2] = dup.off[1];
  EXPECT_FALSE(box_classes(dup, c2));
}
