// Variable-coefficient diffusion operators as per-cell box stencils (pure kernels: no PETSc,
// MPI, allocation or exceptions; shared by the explicit sweep, the matrix assembly and tests).
//
// The operator at cell p is (L u)_p = sum_t w_t u(p + n_t) over the 3^dim box of offsets
// n_t = (dx, dy, dz) in {-1, 0, 1}^dim, t = (dx+1) + 3 (dy+1) + 9 (dz+1). The weights come from
// the coefficients of the cell's 3^dim neighbourhood, c[t * NC + q] = component q at p + n_t.
// A symmetric tensor has NC = 3 components in 2-D (xx, xy, yy) and 6 in 3-D
// (xx, xy, xz, yy, yz, zz); an isotropic coefficient has NC = 1.
//
// tensor_weights (second order, conservative: Sanderson et al. eq. 17 with the tensor-gradient
// terms): div(sigma grad u) discretised from the energy
//   E(u) = 1/2 sum_Q |cell| 2^-dim sum_{corners b of Q} g_b^T sigma_Q g_b,   L = -(1/|cell|) dE/du,
// where Q runs over the dual cells (the 2^dim cells around a grid vertex), sigma_Q is the mean
// of their tensors, and g_b holds the differences (u_hi - u_lo) / h_a along the dim edges of Q
// that meet at its corner b. Equivalently, the flux through a face is the mean over the face's
// dual cells of (sigma_Q g)_a, with the along-face-normal difference of the two cells and the
// transverse differences averaged inside Q. Hence: conservative, symmetric, negative
// semi-definite wherever sigma is positive semi-definite (its Rayleigh quotient is bounded by
// lambda_max(sigma) times the Laplacian's); a diagonal tensor gives a star stencil, a full one
// 9 points in 2-D and 19 in 3-D; sigma = D I gives D times the 5/7-point Laplacian.
//
// tensor_weights_first_order (Witkin & Kass eqs. 6-7): the constant-coefficient mask of the
// cell's own tensor, sum_ab sigma_ab(p) d_a d_b u with the 3-point second differences and the
// 4-point centred mixed differences. It approximates sigma : grad grad u (second order), which
// misses div(sigma grad u) by (div sigma) . grad u: no tensor-gradient terms, so where sigma
// varies it is not consistent with the divergence form (the difference of Sanderson's Fig. 7),
// not conservative and not symmetric. With mirrored ghosts it imposes du/dn = 0 at zero-flux
// walls (not n . sigma grad u = 0).
//
// isotropic_weights: div(D grad u) with the face coefficient the mean of the two cells' D.
#pragma once

#include "models/model.hpp" // MG_HD

#include <cmath>
#include <utility>

namespace morphogen {

template <int Dim> struct TensorLayout {
  static constexpr int nc = Dim == 2 ? 3 : 6;  // symmetric tensor components
  static constexpr int nb = Dim == 2 ? 9 : 27; // box neighbourhood size
  // Component index of sigma_ab.
  MG_HD static constexpr int index(int a, int b) {
    if (a > b) return index(b, a);
    return Dim == 2 ? a + b : (a == 0 ? b : a == 1 ? 2 + b : 5);
  }
  // Box index of offset (dx, dy, dz) (dz ignored in 2-D).
  MG_HD static constexpr int box(int dx, int dy, int dz) {
    return (dx + 1) + 3 * (dy + 1) + (Dim == 3 ? 9 * (dz + 1) : 0);
  }
};

// Second-order conservative weights w[nb] of div(sigma grad u) at the centre cell from the
// tensors of its 2^dim dual cells: sq[q * nc + m], dual cell q with lower cell (bit - 1) per
// axis (bit d of q).
template <int Dim>
MG_HD inline void tensor_weights_dual(const double* sq, const double* inv_h, double* w) {
  using T = TensorLayout<Dim>;
  constexpr int NQ = 1 << Dim; // dual cells around the centre, corners per dual cell
  for (int t = 0; t < T::nb; ++t)
    w[t] = 0.0;
  for (int q = 0; q < NQ; ++q) {
    int l[3] = {0, 0, 0};
    for (int d = 0; d < Dim; ++d)
      l[d] = ((q >> d) & 1) - 1;
    const int bp = (~q) & (NQ - 1); // the centre's corner in this dual cell
    const double* s = sq + q * T::nc;
    for (int b = 0; b < NQ; ++b) {
      const int diff = b ^ bp;
      for (int a = 0; a < Dim; ++a) {
        if (diff & ~(1 << a)) continue; // the centre is not an endpoint of edge a at corner b
        const double dp = ((bp >> a) & 1 ? 1.0 : -1.0) * inv_h[a];
        for (int e = 0; e < Dim; ++e) {
          const double coef = s[T::index(a, e)] * dp * inv_h[e] * (1.0 / NQ);
          const int hi = b | (1 << e), lo = b & ~(1 << e);
          w[T::box(l[0] + (hi & 1), l[1] + ((hi >> 1) & 1), Dim == 3 ? l[2] + (hi >> 2) : 0)] -=
              coef;
          w[T::box(l[0] + (lo & 1), l[1] + ((lo >> 1) & 1), Dim == 3 ? l[2] + (lo >> 2) : 0)] +=
              coef;
        }
      }
    }
  }
}

// The same from the cells' tensors: each dual cell's tensor is the mean of its 2^dim cells.
template <int Dim>
MG_HD inline void tensor_weights(const double* c, const double* inv_h, double* w) {
  using T = TensorLayout<Dim>;
  constexpr int NQ = 1 << Dim;
  double sq[NQ * T::nc];
  for (int q = 0; q < NQ; ++q) {
    int l[3] = {0, 0, 0};
    for (int d = 0; d < Dim; ++d)
      l[d] = ((q >> d) & 1) - 1;
    for (int m = 0; m < T::nc; ++m)
      sq[q * T::nc + m] = 0.0;
    for (int b = 0; b < NQ; ++b) {
      const int t = T::box(l[0] + (b & 1), l[1] + ((b >> 1) & 1), Dim == 3 ? l[2] + (b >> 2) : 0);
      for (int m = 0; m < T::nc; ++m)
        sq[q * T::nc + m] += c[t * T::nc + m] * (1.0 / NQ);
    }
  }
  tensor_weights_dual<Dim>(sq, inv_h, w);
}

// First-order (Witkin-Kass) mask of the centre cell's tensor.
template <int Dim>
MG_HD inline void tensor_weights_first_order(const double* c, const double* inv_h, double* w) {
  using T = TensorLayout<Dim>;
  for (int t = 0; t < T::nb; ++t)
    w[t] = 0.0;
  const double* s = c + T::box(0, 0, 0) * T::nc;
  const int centre = T::box(0, 0, 0);
  for (int a = 0; a < Dim; ++a) {
    int o[3] = {0, 0, 0};
    const double k = s[T::index(a, a)] * inv_h[a] * inv_h[a];
    o[a] = -1;
    w[T::box(o[0], o[1], o[2])] += k;
    o[a] = 1;
    w[T::box(o[0], o[1], o[2])] += k;
    w[centre] -= 2.0 * k;
    for (int b = a + 1; b < Dim; ++b) {
      const double x = 0.5 * s[T::index(a, b)] * inv_h[a] * inv_h[b];
      for (int sa = -1; sa <= 1; sa += 2)
        for (int sb = -1; sb <= 1; sb += 2) {
          int p[3] = {0, 0, 0};
          p[a] = sa;
          p[b] = sb;
          w[T::box(p[0], p[1], p[2])] += sa * sb * x;
        }
    }
  }
}

// div(D grad u) with face coefficients (D_p + D_n) / 2; c[t] = D at p + n_t (NC = 1).
template <int Dim>
MG_HD inline void isotropic_weights(const double* c, const double* inv_h, double* w) {
  using T = TensorLayout<Dim>;
  for (int t = 0; t < T::nb; ++t)
    w[t] = 0.0;
  const int centre = T::box(0, 0, 0);
  for (int a = 0; a < Dim; ++a)
    for (int sa = -1; sa <= 1; sa += 2) {
      int o[3] = {0, 0, 0};
      o[a] = sa;
      const int t = T::box(o[0], o[1], o[2]);
      const double k = 0.5 * (c[centre] + c[t]) * inv_h[a] * inv_h[a];
      w[t] += k;
      w[centre] -= k;
    }
}

enum class DiffusionScheme { Constant, IsotropicField, Tensor, TensorFirstOrder };

// Weights of one scheme (not Constant); nc must match (1 for IsotropicField).
template <int Dim>
MG_HD inline void scheme_weights(DiffusionScheme s, const double* c, const double* inv_h,
                                 double* w) {
  if (s == DiffusionScheme::IsotropicField)
    isotropic_weights<Dim>(c, inv_h, w);
  else if (s == DiffusionScheme::TensorFirstOrder)
    tensor_weights_first_order<Dim>(c, inv_h, w);
  else
    tensor_weights<Dim>(c, inv_h, w);
}

// Largest eigenvalue of a symmetric tensor (components as above); 1 component: the value.
template <int Dim> MG_HD inline double tensor_max_eigenvalue(const double* s);

template <> MG_HD inline double tensor_max_eigenvalue<2>(const double* s) {
  const double m = 0.5 * (s[0] + s[2]), d = 0.5 * (s[0] - s[2]);
  return m + std::sqrt(d * d + s[1] * s[1]);
}

// 3-D: the trigonometric closed form for a symmetric 3x3 matrix (eigenvalues real).
template <> MG_HD inline double tensor_max_eigenvalue<3>(const double* s) {
  const double p1 = s[1] * s[1] + s[2] * s[2] + s[4] * s[4];
  const double q = (s[0] + s[3] + s[5]) / 3.0;
  const double a = s[0] - q, b = s[3] - q, c = s[5] - q;
  const double p2 = a * a + b * b + c * c + 2.0 * p1;
  if (p2 <= 1e-300) return q;
  const double p = std::sqrt(p2 / 6.0);
  // det((S - q I) / p) / 2
  const double r = (a * (b * c - s[4] * s[4]) - s[1] * (s[1] * c - s[4] * s[2]) +
                    s[2] * (s[1] * s[4] - b * s[2])) /
                   (2.0 * p * p * p);
  const double phi = r <= -1 ? M_PI / 3.0 : r >= 1 ? 0.0 : std::acos(r) / 3.0;
  return q + 2.0 * p * std::cos(phi);
}

// Positive definite (Sylvester's criterion on the leading minors).
template <int Dim> MG_HD inline bool tensor_positive_definite(const double* s) {
  if (Dim == 2) return s[0] > 0 && s[0] * s[2] - s[1] * s[1] > 0;
  const double m2 = s[0] * s[3] - s[1] * s[1];
  const double det = s[0] * (s[3] * s[5] - s[4] * s[4]) - s[1] * (s[1] * s[5] - s[4] * s[2]) +
                     s[2] * (s[1] * s[4] - s[3] * s[2]);
  return s[0] > 0 && m2 > 0 && det > 0;
}

// Direct (weight-free) forms of the same operators for the explicit sweep. u points at the
// cell, st[d] is the array stride of axis d.
//
// Second order: (L u)_P = sum_a (F_a+ - F_a-) / h_a with the face flux F the mean over the
// face's 2^(dim-1) dual cells Q of  sigma_Q,aa (u_N - u_P)/h_a (oriented along +a)
//   + sum_{b != a} sigma_Q,ab (d_b(P) + d_b(N)) / (2 h_b),
// d_b(X) the one-sided difference of X along b on Q's side. cq[q] points at the cell's entry of
// the dual-cell tensors (component q), indexed by each dual cell's lower cell.
// The 2-D case written out (the same sums; the generic loop below does not vectorise).
MG_HD inline double tensor_divergence_2d(const double* u, const double* X, const double* Y,
                                         const double* Z, long sy, double hx, double hy) {
  const double uP = u[0], uE = u[1], uW = u[-1], uN = u[sy], uS = u[-sy];
  const double uNE = u[sy + 1], uNW = u[sy - 1], uSE = u[1 - sy], uSW = u[-1 - sy];
  const long sw = -1 - sy; // dual cell below-left
  const double ex = (uE - uP) * hx, wx = (uP - uW) * hx, ny = (uN - uP) * hy, sy_ = (uP - uS) * hy;
  const double fxp = X[0] * ex + Y[0] * 0.5 * (ny + (uNE - uE) * hy) + X[-sy] * ex +
                     Y[-sy] * 0.5 * (sy_ + (uE - uSE) * hy);
  const double fxm = X[-1] * wx + Y[-1] * 0.5 * (ny + (uNW - uW) * hy) + X[sw] * wx +
                     Y[sw] * 0.5 * (sy_ + (uW - uSW) * hy);
  const double fyp = Z[0] * ny + Y[0] * 0.5 * (ex + (uNE - uN) * hx) + Z[-1] * ny +
                     Y[-1] * 0.5 * (wx + (uN - uNW) * hx);
  const double fym = Z[-sy] * sy_ + Y[-sy] * 0.5 * (ex + (uSE - uS) * hx) + Z[sw] * sy_ +
                     Y[sw] * 0.5 * (wx + (uS - uSW) * hx);
  return 0.5 * ((fxp - fxm) * hx + (fyp - fym) * hy);
}

// Flux of dual cell M (bit per transverse axis: 1 = the +side) through the face of the centre
// cell on side Side of axis A, times h_A-scaled differences (all loops fixed at compile time).
template <int Dim, int A, int Side, int M>
MG_HD inline double dual_face_flux(const double* u, const double* const* cq, const long* st,
                                   const double* inv_h, long o) {
  using T = TensorLayout<Dim>;
  constexpr auto up = [](int b) { return ((M >> (b < A ? b : b - 1)) & 1) != 0; };
  const long oN = Side ? st[A] : -st[A];
  long ql = o + (Side ? 0 : -st[A]); // the dual cell's lower cell (o: the centre's offset in cq)
  for (int b = 0; b < Dim; ++b)
    if (b != A && !up(b)) ql -= st[b];
  double f = cq[T::index(A, A)][ql] * (Side ? u[oN] - u[0] : u[0] - u[oN]) * inv_h[A];
  for (int b = 0; b < Dim; ++b) {
    if (b == A) continue;
    const double dP = up(b) ? u[st[b]] - u[0] : u[0] - u[-st[b]];
    const double dN = up(b) ? u[oN + st[b]] - u[oN] : u[oN] - u[oN - st[b]];
    f += cq[T::index(A, b)][ql] * 0.5 * (dP + dN) * inv_h[b];
  }
  return f;
}

template <int Dim, int A, int Side, int... M>
MG_HD inline double face_flux(const double* u, const double* const* cq, const long* st,
                              const double* inv_h, long o, std::integer_sequence<int, M...>) {
  return (dual_face_flux<Dim, A, Side, M>(u, cq, st, inv_h, o) + ...) * (1.0 / sizeof...(M));
}

template <int Dim, int... A>
MG_HD inline double tensor_divergence_axes(const double* u, const double* const* cq, const long* st,
                                           const double* inv_h, long o,
                                           std::integer_sequence<int, A...>) {
  constexpr auto faces = std::make_integer_sequence<int, 1 << (Dim - 1)>{};
  return (((face_flux<Dim, A, 1>(u, cq, st, inv_h, o, faces) -
            face_flux<Dim, A, 0>(u, cq, st, inv_h, o, faces)) *
           inv_h[A]) +
          ...);
}

template <int Dim>
MG_HD inline double tensor_divergence(const double* u, const double* const* cq, const long* st,
                                      const double* inv_h) {
  if constexpr (Dim == 2)
    return tensor_divergence_2d(u, cq[0], cq[1], cq[2], st[1], inv_h[0], inv_h[1]);
  else
    return tensor_divergence_axes<Dim>(u, cq, st, inv_h, 0, std::make_integer_sequence<int, Dim>{});
}

// First order (Witkin-Kass mask of the cell's own tensor c[q] at the cell).
template <int Dim>
MG_HD inline double tensor_divergence_first_order(const double* u, const double* const* c,
                                                  const long* st, const double* inv_h) {
  using T = TensorLayout<Dim>;
  double v = 0.0;
  for (int a = 0; a < Dim; ++a) {
    v += c[T::index(a, a)][0] * (u[st[a]] - 2.0 * u[0] + u[-st[a]]) * inv_h[a] * inv_h[a];
    for (int b = a + 1; b < Dim; ++b)
      v += c[T::index(a, b)][0] * 0.5 * inv_h[a] * inv_h[b] *
           (u[st[a] + st[b]] - u[st[a] - st[b]] - u[-st[a] + st[b]] + u[-st[a] - st[b]]);
  }
  return v;
}

// Isotropic field: face coefficients the mean of the two cells' D (c[0] at the cell).
template <int Dim>
MG_HD inline double isotropic_divergence(const double* u, const double* const* c, const long* st,
                                         const double* inv_h) {
  const double* D = c[0];
  double v = 0.0;
  for (int a = 0; a < Dim; ++a)
    v += 0.5 * inv_h[a] * inv_h[a] *
         ((D[0] + D[st[a]]) * (u[st[a]] - u[0]) - (D[0] + D[-st[a]]) * (u[0] - u[-st[a]]));
  return v;
}

// One row of n cells: out[i] = (L u) at cell i (coef[q]: the dual-cell tensors for Tensor, the
// cell's coefficients otherwise, all pointing at the row's first cell).
template <int Dim, DiffusionScheme S>
inline void diffusion_row(int n, const double* const* coef, const long* st, const double* u,
                          const double* inv_h, double* out) {
  constexpr int NC = S == DiffusionScheme::IsotropicField ? 1 : TensorLayout<Dim>::nc;
  if constexpr (Dim == 2 && S == DiffusionScheme::Tensor) {
    const double* __restrict__ X = coef[0];
    const double* __restrict__ Y = coef[1];
    const double* __restrict__ Z = coef[2];
    const long sy = st[1];
    const double hx = inv_h[0], hy = inv_h[1];
#pragma GCC ivdep
    for (int i = 0; i < n; ++i)
      out[i] = tensor_divergence_2d(u + i, X + i, Y + i, Z + i, sy, hx, hy);
    return;
  }
  if constexpr (S == DiffusionScheme::Tensor) {
    // Fixed component pointers and a running offset (so the loop vectorises).
    const double* c[NC];
    for (int q = 0; q < NC; ++q)
      c[q] = coef[q];
    const long s3[3] = {st[0], st[1], st[2]};
    const double ih[3] = {inv_h[0], inv_h[1], inv_h[2]};
#pragma GCC ivdep
    for (int i = 0; i < n; ++i)
      out[i] =
          tensor_divergence_axes<Dim>(u + i, c, s3, ih, i, std::make_integer_sequence<int, Dim>{});
    return;
  }
  const double* c[NC];
  for (int i = 0; i < n; ++i) {
    for (int q = 0; q < NC; ++q)
      c[q] = coef[q] + i;
    if constexpr (S == DiffusionScheme::Tensor)
      out[i] = tensor_divergence<Dim>(u + i, c, st, inv_h);
    else if constexpr (S == DiffusionScheme::TensorFirstOrder)
      out[i] = tensor_divergence_first_order<Dim>(u + i, c, st, inv_h);
    else
      out[i] = isotropic_divergence<Dim>(u + i, c, st, inv_h);
  }
}

} // namespace morphogen
