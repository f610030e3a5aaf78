// Witkin-Kass surface-metric correction of a diffusion tensor (Witkin & Kass 1991, section 4).
//
// A pattern grown on the 2-D parameter grid (u, v) = (x, y) is shown on a parametric surface
// X(u, v) = (x(u,v), y(u,v), z(u,v)). To make the pattern look undistorted *on the surface*,
// the diffusion tensor used in parameter space is the desired surface tensor pulled back
// through the local linear map J = dX/du.
//
// Notation (WK section 4). J = [X_u X_v] is 3x2 (X_u = dX/du, X_v = dX/dv); M = J^T J is the
// metric tensor, m11 = X_u.X_u, m12 = X_u.X_v, m22 = X_v.X_v, det M = m11 m22 - m12^2 (> 0 for a
// regular map). V is the 2x2 matrix with V^T M V = I (so F = J V = [e1 e2] is an orthonormal
// basis of the tangent plane) and v21 = 0 (so e1 = X_u / |X_u|: WK's reference direction J alpha).
// With positive diagonal V is unique: upper triangular,
//
//       V = [ 1/sqrt(m11)   -m12 / (sqrt(m11) sqrt(det M)) ]      V^-1 = WK eq. 8:
//           [ 0              sqrt(m11) / sqrt(det M)       ]      (1/sqrt(m11)) [m11 m12        ]
//                                                                               [0   sqrt(det M)]
// and e2 = J V[:,1] is X_v made orthogonal to X_u (Gram-Schmidt) and normalised; (e1, e2) has the
// orientation of (X_u, X_v), i.e. e1 x e2 is along X_u x X_v.
//
// The desired surface tensor A = [a11 a12; a12 a22] (sigma_surface) is given in the frame
// (e1, e2): e.g. from (theta, l1, l2) with theta measured on the surface from X_u towards e2.
// The tensor to use in parameter space (sigma_param) is
//
//       sigma_param = V A V^T                                                  (*)
//   i.e.  s11 = p^2 a11 + 2 p q a12 + q^2 a22,   s12 = p r a12 + q r a22,   s22 = r^2 a22
//   with  p = 1/sqrt(m11),  q = -m12 / (sqrt(m11) sqrt(det M)),  r = sqrt(m11) / sqrt(det M).
//
// Why (*) (locally linear map, as WK assume). Near a point, X - X0 = J (u - u0) = F w with w the
// orthonormal tangent coordinates, so u - u0 = V w and d/dw = V^T d/du. The surface diffusion
// term sum_ij a_ij d2C/dw_i dw_j = tr(A H_w) = tr(A V^T H_u V) = tr((V A V^T) H_u): the
// parameter-space operator with tensor V A V^T *is* the surface operator. Equivalently (the
// diffusion tensor is the covariance rate of the random walk), a walk in (u, v) with covariance
// rate sigma_param moves on the surface with covariance rate J sigma_param J^T = F A F^T: the
// desired tensor expressed in 3-D (the tests check this). Example: X = (2u, v, 0) gives
// sigma_param = diag(a11/4, a22): a unit of surface length is half a unit of u.
//
// Note on WK's printed summary "A^ = V~^T A V~" (V~ = their eq. 8 = V^-1): taken literally it
// gives diag(4 a11, a22) for the stretch above, the inverse of the correction; their sentence
// "post-multiply A by the inverse of dv/du and pre-multiply by the inverse transpose" gives
// V^T A V, which equals (*) only when V is diagonal (no shear). (*) is the form derived above.
//
// What is ignored (and why): the locally linear correction is exact for a linear map (constant
// J) and first-order otherwise. The exact Laplace-Beltrami operator in parameter coordinates is
//     (1/sqrt(g)) d_i( sqrt(g) sigma^ij d_j C ),   sqrt(g) = sqrt(det M) (area element),
// which differs from div(sigma_param grad C) by first-derivative (drift) terms in
// d_i sqrt(g) / sqrt(g) - the same order as the second-derivative-of-X effects WK neglect. We
// follow WK and do NOT include sqrt(det M): the result is the tensor alone (for constant J the
// factor cancels exactly). Consequence: the parameter-space scheme conserves the integral of C
// over (u, v), not over surface area. A caller wanting the exact operator can use
// surface_area_element(): tensor sqrt(g) * sigma_param inside the divergence and the diffusion
// rate divided by sqrt(g).
//
// The inline functions below are pure (no PETSc, MPI, allocation or exceptions): kernels and tests
// can use them. SurfaceMap (in surface_metric.cpp) evaluates the user's muParser expressions.
#pragma once

#include <cmath>
#include <memory>
#include <string>

namespace mu {
class Parser;
}

namespace morphogen {

// Metric M = J^T J as (m11, m12, m22); returns det M. J column-major 3x2: J[0..2] = dX/du,
// J[3..5] = dX/dv.
inline double surface_metric(const double J[6], double M[3]) {
  M[0] = J[0] * J[0] + J[1] * J[1] + J[2] * J[2];
  M[1] = J[0] * J[3] + J[1] * J[4] + J[2] * J[5];
  M[2] = J[3] * J[3] + J[4] * J[4] + J[5] * J[5];
  return M[0] * M[2] - M[1] * M[1];
}

// True when J is (numerically) rank deficient: X_u or X_v zero or not finite, |X_u| / |X_v|
// beyond 1e6 or below 1e-6, or the angle between them below ~1e-6 rad (det M <= 1e-12 m11 m22).
// Scale-free: multiplying J by a number does not change the answer. (SurfaceMap applies it to
// [Lx X_u, Ly X_v], so that the units of u and v do not matter either.)
inline bool surface_map_degenerate(const double J[6]) {
  double M[3];
  const double det = surface_metric(J, M);
  const double lo = M[0] < M[2] ? M[0] : M[2], hi = M[0] < M[2] ? M[2] : M[0];
  const double scale = M[0] * M[2];
  return !(std::isfinite(det) && std::isfinite(scale) && scale > 0.0 && lo > 1e-12 * hi &&
           det > 1e-12 * scale);
}

// Area element sqrt(det M) (surface area per unit parameter area). Not used by the correction.
inline double surface_area_element(const double J[6]) {
  double M[3];
  return std::sqrt(surface_metric(J, M));
}

// V (row-major: V[0] = v11, V[1] = v12, V[2] = v21 = 0, V[3] = v22) with V^T M V = I, v21 = 0,
// positive diagonal. Requires !surface_map_degenerate(J).
inline void surface_frame(const double J[6], double V[4]) {
  double M[3];
  const double det = surface_metric(J, M);
  const double sm = std::sqrt(M[0]), sd = std::sqrt(det);
  V[0] = 1.0 / sm;
  V[1] = -M[1] / (sm * sd);
  V[2] = 0.0;
  V[3] = sm / sd;
}

// sigma_param = V A V^T, A = [s11 s12; s12 s22] = sigma_surface in the tangent frame (e1, e2)
// (e1 along dX/du). In and out as (s11, s12, s22). Requires !surface_map_degenerate(J)
// (otherwise the result is inf/NaN). sigma_param may alias sigma_surface.
inline void surface_corrected_tensor(const double J[6], const double sigma_surface[3],
                                     double sigma_param[3]) {
  double V[4];
  surface_frame(J, V);
  const double p = V[0], q = V[1], r = V[3];
  const double a11 = sigma_surface[0], a12 = sigma_surface[1], a22 = sigma_surface[2];
  sigma_param[0] = p * p * a11 + 2.0 * p * q * a12 + q * q * a22;
  sigma_param[1] = p * r * a12 + q * r * a22;
  sigma_param[2] = r * r * a22;
}

// The parametric surface X(u, v) = (x, y, z) given by three muParser expressions in the
// variables u, v (the cell-centre coordinates x and y of the 2-D grid) and the constants Lx, Ly
// (domain lengths) and pi (muParser's _pi works too). The Jacobian is by central differences
// with steps 1e-6 Lx and 1e-6 Ly (second order: error ~1e-12 L^2 |X'''| + 1e-10 |X| / L).
// Errors (UserError): a bad expression (naming -surface_x/-surface_y/-surface_z, the text and
// muParser's message), a non-finite value, and a degenerate Jacobian, naming the point (u, v).
// Not thread-safe (one parser state per object); not copyable.
class SurfaceMap {
public:
  SurfaceMap(const std::string& x_expr, const std::string& y_expr, const std::string& z_expr,
             double Lx, double Ly);
  ~SurfaceMap();
  SurfaceMap(const SurfaceMap&) = delete;
  SurfaceMap& operator=(const SurfaceMap&) = delete;

  // X(u, v).
  void position(double u, double v, double X[3]);
  // J (column-major 3x2: J[0..2] = dX/du, J[3..5] = dX/dv) at (u, v); throws UserError when it is
  // degenerate (surface_map_degenerate of [Lx dX/du, Ly dX/dv]).
  void jacobian(double u, double v, double J[6]);
  // jacobian() then surface_corrected_tensor(): the parameter-space tensor at (u, v).
  void corrected_tensor(double u, double v, const double sigma_surface[3], double sigma_param[3]);

  static const char* option_name(int axis); // "-surface_x", "-surface_y", "-surface_z"

private:
  double eval(int axis);
  std::string expr_[3];
  std::unique_ptr<mu::Parser> parser_[3];
  double u_ = 0.0, v_ = 0.0, L_[2];
};

} // namespace morphogen
