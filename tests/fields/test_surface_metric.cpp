// Witkin-Kass surface-metric correction (src/fields/surface_metric.hpp): the pure tensor kernel
// and the muParser surface map.
#include "fields/surface_metric.hpp"

#include "core/user_error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

using morphogen::SurfaceMap;
using morphogen::UserError;

namespace {

constexpr double kPi = 3.14159265358979323846;

// (s11, s12, s22) -> full 2x2 row-major.
void full(const double s[3], double A[4]) {
  A[0] = s[0], A[1] = s[1], A[2] = s[1], A[3] = s[2];
}

// Surface tensor from (theta, l1, l2): R^T diag(l1, l2) R, R = [[c, s], [-s, c]] (Sanderson
// eqs 12-16): principal direction (cos theta, sin theta) with l1, in the frame (e1, e2).
void from_angle(double theta, double l1, double l2, double s[3]) {
  const double c = std::cos(theta), sn = std::sin(theta);
  s[0] = l1 * c * c + l2 * sn * sn;
  s[1] = (l1 - l2) * c * sn;
  s[2] = l1 * sn * sn + l2 * c * c;
}

// Column a of the 3x2 column-major J.
double Jc(const double J[6], int row, int col) {
  return J[3 * col + row];
}

// J S J^T (3x3, row-major) for 2x2 S.
void push_forward(const double J[6], const double S[4], double out[9]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double sum = 0;
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          sum += Jc(J, i, a) * S[2 * a + b] * Jc(J, j, b);
      out[3 * i + j] = sum;
    }
}

// F = J V (3x2 column-major) from the row-major V.
void frame_vectors(const double J[6], const double V[4], double F[6]) {
  for (int col = 0; col < 2; ++col)
    for (int row = 0; row < 3; ++row)
      F[3 * col + row] = Jc(J, row, 0) * V[col] + Jc(J, row, 1) * V[2 + col];
}

void expect_message(const std::function<void()>& f, const std::string& part1,
                    const std::string& part2 = "", const std::string& part3 = "") {
  try {
    f();
    ADD_FAILURE() << "no UserError (expected one mentioning " << part1 << ")";
  } catch (const UserError& e) {
    const std::string msg = e.what();
    for (const auto& p : {part1, part2, part3})
      EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

const double kSigma[3] = {1.3, 0.4, 0.7}; // SPD: 1.3 * 0.7 > 0.16
const double kShear[6] = {1.0, 0.3, 0.4, 0.7, 1.5, -0.2};

} // namespace

// (a) --------------------------------------------------------------------------- identity map

TEST(SurfaceMetric, IdentityLeavesTensorUnchanged) {
  const double J[6] = {1, 0, 0, 0, 1, 0};
  double out[3];
  morphogen::surface_corrected_tensor(J, kSigma, out);
  for (int c = 0; c < 3; ++c)
    EXPECT_DOUBLE_EQ(out[c], kSigma[c]);
  EXPECT_DOUBLE_EQ(morphogen::surface_area_element(J), 1.0);

  // The same through the muParser map, at a few points (z = 0 plane; Lx, Ly unused).
  SurfaceMap map("u", "v", "0", 10.0, 5.0);
  for (double u : {0.05, 3.0, 9.95})
    for (double v : {0.05, 2.5}) {
      double Jm[6], X[3];
      map.position(u, v, X);
      EXPECT_DOUBLE_EQ(X[0], u);
      EXPECT_DOUBLE_EQ(X[1], v);
      EXPECT_DOUBLE_EQ(X[2], 0.0);
      map.corrected_tensor(u, v, kSigma, out);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(out[c], kSigma[c], 1e-9);
      map.jacobian(u, v, Jm);
      for (int c = 0; c < 6; ++c)
        EXPECT_NEAR(Jm[c], J[c], 1e-9);
    }
}

// (b) ----------------------------------------------------------------------- uniform stretch

TEST(SurfaceMetric, UniformStretch) {
  // X = (2u, v, 0): one unit of surface length along X_u is half a unit of u, so the diffusion
  // rate along u in parameter space is a quarter: diag(a11/4, a22), off-diagonal a12/2.
  const double J[6] = {2, 0, 0, 0, 1, 0};
  double out[3];
  morphogen::surface_corrected_tensor(J, kSigma, out);
  EXPECT_DOUBLE_EQ(out[0], kSigma[0] / 4);
  EXPECT_DOUBLE_EQ(out[1], kSigma[1] / 2);
  EXPECT_DOUBLE_EQ(out[2], kSigma[2]);
  const double diag[3] = {1.0, 0.0, 3.0};
  morphogen::surface_corrected_tensor(J, diag, out);
  EXPECT_DOUBLE_EQ(out[0], 0.25);
  EXPECT_DOUBLE_EQ(out[1], 0.0);
  EXPECT_DOUBLE_EQ(out[2], 3.0);
  EXPECT_DOUBLE_EQ(morphogen::surface_area_element(J), 2.0);

  SurfaceMap map("2*u", "v", "0", 1.0, 1.0);
  map.corrected_tensor(0.3, 0.6, kSigma, out);
  EXPECT_NEAR(out[0], kSigma[0] / 4, 1e-9);
  EXPECT_NEAR(out[1], kSigma[1] / 2, 1e-9);
  EXPECT_NEAR(out[2], kSigma[2], 1e-9);

  // Stretch along v (X = (u, 3v, 0)) and a rigid rotation out of the plane change nothing but
  // the v-rate (1/9) and nothing at all, respectively.
  const double Jv[6] = {1, 0, 0, 0, 3, 0};
  morphogen::surface_corrected_tensor(Jv, kSigma, out);
  EXPECT_DOUBLE_EQ(out[0], kSigma[0]);
  EXPECT_DOUBLE_EQ(out[1], kSigma[1] / 3);
  EXPECT_NEAR(out[2], kSigma[2] / 9, 1e-15);
  const double c = std::cos(0.7), s = std::sin(0.7);
  const double Jr[6] = {c, 0, s, 0, 1, 0}; // X_u tilted towards z, still orthonormal to X_v
  morphogen::surface_corrected_tensor(Jr, kSigma, out);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(out[k], kSigma[k], 1e-15);
}

// (c) ------------------------------------------------------------------------ sheared linear

TEST(SurfaceMetric, ShearedLinearMapReproducesSurfaceTensor) {
  // X = (u + 0.7 v, 0.3 u + 1.5 v, 0.4 u - 0.2 v): stretch, shear and a tilt out of the plane.
  const double J[6] = {1.0, 0.3, 0.4, 0.7, 1.5, -0.2};
  double V[4], F[6];
  morphogen::surface_frame(J, V);
  EXPECT_EQ(V[2], 0.0); // v21 = 0
  EXPECT_GT(V[0], 0.0);
  EXPECT_GT(V[3], 0.0);
  frame_vectors(J, V, F);
  // J V orthonormal
  double g[3] = {0, 0, 0};
  for (int r = 0; r < 3; ++r) {
    g[0] += F[r] * F[r];
    g[1] += F[r] * F[3 + r];
    g[2] += F[3 + r] * F[3 + r];
  }
  EXPECT_NEAR(g[0], 1.0, 1e-14);
  EXPECT_NEAR(g[1], 0.0, 1e-14);
  EXPECT_NEAR(g[2], 1.0, 1e-14);
  // e1 along X_u (WK's reference direction J alpha), e1 x e2 along X_u x X_v
  const double nu = std::sqrt(J[0] * J[0] + J[1] * J[1] + J[2] * J[2]);
  for (int r = 0; r < 3; ++r)
    EXPECT_NEAR(F[r], J[r] / nu, 1e-15);
  const double n1[3] = {J[1] * J[5] - J[2] * J[4], J[2] * J[3] - J[0] * J[5],
                        J[0] * J[4] - J[1] * J[3]};
  const double n2[3] = {F[1] * F[5] - F[2] * F[4], F[2] * F[3] - F[0] * F[5],
                        F[0] * F[4] - F[1] * F[3]};
  EXPECT_GT(n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2], 0.0);

  for (double theta : {0.0, 0.4, 1.1, 2.0, -0.8}) {
    double sigma_surface[3], sigma_param[3], A[4], S[4], lhs[9], rhs[9];
    from_angle(theta, 2.0, 0.3, sigma_surface);
    morphogen::surface_corrected_tensor(J, sigma_surface, sigma_param);
    full(sigma_surface, A);
    full(sigma_param, S);
    push_forward(J, S, lhs); // J sigma_param J^T: the parameter-space walk seen on the surface
    push_forward(F, A, rhs); // F A F^T: the desired surface tensor in 3-D
    for (int k = 0; k < 9; ++k)
      EXPECT_NEAR(lhs[k], rhs[k], 1e-13) << "theta " << theta;
    // The principal direction on the surface is cos(theta) e1 + sin(theta) e2, rate 2.0.
    double d[3], Ld[3];
    for (int r = 0; r < 3; ++r)
      d[r] = std::cos(theta) * F[r] + std::sin(theta) * F[3 + r];
    for (int r = 0; r < 3; ++r)
      Ld[r] = lhs[3 * r] * d[0] + lhs[3 * r + 1] * d[1] + lhs[3 * r + 2] * d[2];
    for (int r = 0; r < 3; ++r)
      EXPECT_NEAR(Ld[r], 2.0 * d[r], 1e-13);
    // The shear case tells (*) = V A V^T apart from V^T A V (WK's prose) when A is anisotropic.
    double vtav_diff = 0;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        double sum = 0;
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            sum += V[2 * a + i] * A[2 * a + b] * V[2 * b + j];
        vtav_diff = std::max(vtav_diff, std::abs(sum - S[2 * i + j]));
      }
    EXPECT_GT(vtav_diff, 1e-2) << "theta " << theta;
  }

  // Isotropic surface diffusion: V V^T = M^-1 (the inverse metric of Laplace-Beltrami).
  const double iso[3] = {1.0, 0.0, 1.0};
  double out[3], M[3];
  const double det = morphogen::surface_metric(J, M);
  morphogen::surface_corrected_tensor(J, iso, out);
  EXPECT_NEAR(out[0], M[2] / det, 1e-14);
  EXPECT_NEAR(out[1], -M[1] / det, 1e-14);
  EXPECT_NEAR(out[2], M[0] / det, 1e-14);

  // Through muParser: the finite-difference Jacobian of a linear map is exact up to rounding.
  SurfaceMap map("u + 0.7*v", "0.3*u + 1.5*v", "0.4*u - 0.2*v", 4.0, 2.0);
  double Jm[6], a[3], b[3];
  map.jacobian(1.3, 0.9, Jm);
  for (int k = 0; k < 6; ++k)
    EXPECT_NEAR(Jm[k], J[k], 1e-9);
  morphogen::surface_corrected_tensor(J, kSigma, a);
  map.corrected_tensor(1.3, 0.9, kSigma, b);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(a[k], b[k], 1e-8);
}

// (d) ----------------------------------------------------- finite differences on curved maps

TEST(SurfaceMetric, TorusJacobianMatchesAnalytic) {
  const double Lx = 64.0, Ly = 32.0, R = 3.0, r = 1.0;
  SurfaceMap map("(3 + cos(2*_pi*v/Ly)) * cos(2*_pi*u/Lx)",
                 "(3 + cos(2*_pi*v/Ly)) * sin(2*_pi*u/Lx)", "sin(2*pi*v/Ly)", Lx, Ly);
  for (double u : {0.25, 10.0, 31.7, 63.75})
    for (double v : {0.25, 8.0, 16.3, 31.75}) {
      const double a = 2 * kPi * u / Lx, b = 2 * kPi * v / Ly;
      const double ka = 2 * kPi / Lx, kb = 2 * kPi / Ly;
      const double ref[6] = {-(R + r * std::cos(b)) * std::sin(a) * ka,
                             (R + r * std::cos(b)) * std::cos(a) * ka,
                             0.0,
                             -r * std::sin(b) * kb * std::cos(a),
                             -r * std::sin(b) * kb * std::sin(a),
                             r * std::cos(b) * kb};
      double J[6], X[3];
      map.jacobian(u, v, J);
      for (int k = 0; k < 6; ++k)
        EXPECT_NEAR(J[k], ref[k], 1e-6) << "u " << u << " v " << v << " k " << k;
      map.position(u, v, X);
      EXPECT_NEAR(X[0], (R + r * std::cos(b)) * std::cos(a), 1e-11);
      EXPECT_NEAR(X[2], r * std::sin(b), 1e-11);
      // Metric of the torus: m11 = ((R + r cos b) ka)^2, m12 = 0, m22 = (r kb)^2.
      double M[3];
      morphogen::surface_metric(J, M);
      EXPECT_NEAR(M[0], std::pow((R + r * std::cos(b)) * ka, 2), 1e-6);
      EXPECT_NEAR(M[1], 0.0, 1e-6);
      EXPECT_NEAR(M[2], std::pow(r * kb, 2), 1e-6);
    }
}

TEST(SurfaceMetric, SpherePatchJacobianMatchesAnalytic) {
  // Longitude lam = 2 pi u / Lx, colatitude phi = pi (0.1 + 0.8 v / Ly) (away from the poles).
  const double Lx = 100.0, Ly = 50.0, Rs = 2.5;
  SurfaceMap map("2.5*sin(pi*(0.1+0.8*v/Ly))*cos(2*pi*u/Lx)",
                 "2.5*sin(pi*(0.1+0.8*v/Ly))*sin(2*pi*u/Lx)", "2.5*cos(pi*(0.1+0.8*v/Ly))", Lx, Ly);
  for (double u : {0.5, 33.3, 99.5})
    for (double v : {0.5, 20.0, 49.5}) {
      const double lam = 2 * kPi * u / Lx, phi = kPi * (0.1 + 0.8 * v / Ly);
      const double dl = 2 * kPi / Lx, dp = 0.8 * kPi / Ly;
      const double ref[6] = {-Rs * std::sin(phi) * std::sin(lam) * dl,
                             Rs * std::sin(phi) * std::cos(lam) * dl,
                             0.0,
                             Rs * std::cos(phi) * std::cos(lam) * dp,
                             Rs * std::cos(phi) * std::sin(lam) * dp,
                             -Rs * std::sin(phi) * dp};
      double J[6];
      map.jacobian(u, v, J);
      for (int k = 0; k < 6; ++k)
        EXPECT_NEAR(J[k], ref[k], 1e-6) << "u " << u << " v " << v << " k " << k;
      // Corrected tensor through FD and analytic Jacobians agree too.
      double a[3], b[3];
      morphogen::surface_corrected_tensor(J, kSigma, a);
      morphogen::surface_corrected_tensor(ref, kSigma, b);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(a[k], b[k], 1e-6 * std::abs(b[0] + b[2]));
    }
}

// (e) -------------------------------------------------------------------------------- errors

TEST(SurfaceMetric, BadExpressionNamesOption) {
  expect_message([] { SurfaceMap m("sin(u", "v", "0", 1, 1); }, "-surface_x", "sin(u");
  expect_message([] { SurfaceMap m("u", "v + w", "0", 1, 1); }, "-surface_y v + w",
                 "unknown variable 'w'");
  expect_message([] { SurfaceMap m("u", "v", " ", 1, 1); }, "-surface_z", "empty");
  expect_message([] { SurfaceMap m("u", "v", "x", 1, 1); }, "-surface_z x", "'x'");
  expect_message([] { SurfaceMap m("u*", "v", "0", 1, 1); }, "-surface_x u*: ");
  expect_message([] { SurfaceMap m("u", "foo(v)", "0", 1, 1); }, "-surface_y foo(v): ");
  EXPECT_NO_THROW(SurfaceMap("u*Lx/Ly", "sin(pi*v) + cos(_pi*u)", "1/u", 1, 1)); // inf at u=0 ok
  // Parses, but not finite at the point: names the option and the point.
  SurfaceMap m("u", "v", "sqrt(u - 0.5)", 1, 1);
  expect_message(
      [&] {
        double X[3];
        m.position(0.25, 0.75, X);
      },
      "-surface_z", "sqrt(u - 0.5)", "(u, v) = (0.25, 0.75)");
  expect_message(
      [&] {
        double J[6];
        m.jacobian(0.25, 0.75, J);
      },
      "-surface_z", "evaluates to", "(u, v) = (0.25, 0.75)");
}

TEST(SurfaceMetric, DegenerateMapNamesPoint) {
  // Rank-1 everywhere: X_u parallel to X_v.
  SurfaceMap line("u + v", "2*u + 2*v", "0", 1, 1);
  expect_message(
      [&] {
        double J[6];
        line.jacobian(0.5, 0.25, J);
      },
      "degenerate", "(u, v) = (0.5, 0.25)", "-surface_x u + v");
  // Regular except at the pole v = 0 of a sphere (X_u = 0 there).
  SurfaceMap sphere("sin(v)*cos(u)", "sin(v)*sin(u)", "cos(v)", 2 * kPi, kPi);
  double J[6];
  EXPECT_NO_THROW(sphere.jacobian(1.0, 1.0, J));
  expect_message([&] { sphere.jacobian(1.0, 0.0, J); }, "degenerate", "(u, v) = (1, 0)",
                 "-surface_z cos(v)");
  double out[3];
  expect_message([&] { sphere.corrected_tensor(2.0, kPi, kSigma, out); }, "degenerate");
  // The pure test, scale-free.
  const double zero[6] = {0, 0, 0, 0, 1, 0};
  const double par[6] = {1e-8, 2e-8, 0, 2e-8, 4e-8, 0};
  const double tiny[6] = {1e-8, 0, 0, 0, 1e-8, 0};
  const double thin[6] = {1e-7, 0, 0, 0, 1, 0}; // |X_u| / |X_v| = 1e-7
  const double nan[6] = {std::nan(""), 0, 0, 0, 1, 0};
  EXPECT_TRUE(morphogen::surface_map_degenerate(zero));
  EXPECT_TRUE(morphogen::surface_map_degenerate(par));
  EXPECT_TRUE(morphogen::surface_map_degenerate(nan));
  EXPECT_TRUE(morphogen::surface_map_degenerate(thin));
  EXPECT_FALSE(morphogen::surface_map_degenerate(tiny));
  EXPECT_FALSE(morphogen::surface_map_degenerate(kShear));
}
