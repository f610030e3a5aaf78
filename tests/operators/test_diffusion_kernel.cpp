// Variable-coefficient diffusion kernels (operators/diffusion_kernel.hpp), serial:
//  (a) the per-cell weights (tensor_weights, tensor_weights_first_order, isotropic_weights)
//      applied to random u equal the direct explicit forms (diffusion_row over a row of cells,
//      i.e. tensor_divergence fed with dual-cell tensors = means over the 2^dim cells,
//      tensor_divergence_first_order, isotropic_divergence) to 1e-12 relative, for random
//      positive definite neighbourhoods in 2-D and 3-D and unequal spacings;
//  (b) sigma = D I gives D times the 5/7-point Laplacian;
//  (c) row sums vanish; a constant tensor gives weights symmetric under n -> -n, and then the
//      first-order masks equal the second-order weights;
//  (d) exactness: linear u with a linearly varying tensor (second order and the isotropic
//      field), quadratic u with a constant tensor (both tensor schemes); the first-order
//      (Witkin-Kass) masks are the non-divergence form sigma:grad grad u: exact for quadratic u
//      with a linearly varying tensor, missing the tensor-gradient terms (div sigma).grad u of
//      div(sigma grad u) (not consistent with it where sigma varies);
//  (e) the energy form on small periodic grids with random SPD cell tensors: the assembled
//      matrix is symmetric, conservative and negative semi-definite, and
//      u^T L u >= lambda_max u^T L_iso u (the Rayleigh bound of the explicit dt limit), so its
//      spectrum lies in [-lambda_max rho(L_iso), 0];
//  plus tensor_max_eigenvalue / tensor_positive_definite against a Jacobi eigen-solver.
#include "operators/diffusion_kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

using namespace morphogen;

namespace {

// ---------------------------------------------------------------------------------------------
// Small dense symmetric eigen-solver (cyclic Jacobi), eigenvalues only.
std::vector<double> jacobi_eigenvalues(std::vector<double> a, int n) {
  auto A = [&](int i, int j) -> double& { return a[static_cast<size_t>(i) * n + j]; };
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0, diag = 0;
    for (int i = 0; i < n; ++i) {
      diag += A(i, i) * A(i, i);
      for (int j = i + 1; j < n; ++j)
        off += A(i, j) * A(i, j);
    }
    if (off <= 1e-30 * (diag + off) || off == 0.0) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        if (A(p, q) == 0.0) continue;
        const double theta = (A(q, q) - A(p, p)) / (2 * A(p, q));
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; ++k) { // A <- A J (columns p, q)
          const double akp = A(k, p), akq = A(k, q);
          A(k, p) = c * akp - s * akq;
          A(k, q) = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) { // A <- J^T A (rows p, q)
          const double apk = A(p, k), aqk = A(q, k);
          A(p, k) = c * apk - s * aqk;
          A(q, k) = s * apk + c * aqk;
        }
      }
  }
  std::vector<double> ev(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    ev[i] = A(i, i);
  std::sort(ev.begin(), ev.end());
  return ev;
}

// ---------------------------------------------------------------------------------------------
// Random symmetric positive definite tensors, components in TensorLayout order.
template <int Dim> std::array<double, 6> random_spd(std::mt19937_64& rng, double lo = 0.2) {
  using T = TensorLayout<Dim>;
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  double m[3][3];
  for (auto& r : m)
    for (double& v : r)
      v = U(rng);
  std::array<double, 6> s{};
  for (int a = 0; a < Dim; ++a)
    for (int b = a; b < Dim; ++b) {
      double v = a == b ? lo : 0.0;
      for (int e = 0; e < Dim; ++e)
        v += m[a][e] * m[b][e];
      s[T::index(a, b)] = v;
    }
  return s;
}

template <int Dim> double component(const double* s, int a, int b) {
  return s[TensorLayout<Dim>::index(a, b)];
}

// Full symmetric matrix of a tensor (row-major Dim x Dim).
template <int Dim> std::vector<double> full(const double* s) {
  std::vector<double> m(Dim * Dim);
  for (int a = 0; a < Dim; ++a)
    for (int b = 0; b < Dim; ++b)
      m[a * Dim + b] = component<Dim>(s, a, b);
  return m;
}

template <int Dim> constexpr int kCentre = TensorLayout<Dim>::box(0, 0, 0);

template <int Dim> double apply(const double* w, const double* u) {
  double v = 0;
  for (int t = 0; t < TensorLayout<Dim>::nb; ++t)
    v += w[t] * u[t];
  return v;
}

template <int Dim> double abs_apply(const double* w, const double* u) {
  double v = 0;
  for (int t = 0; t < TensorLayout<Dim>::nb; ++t)
    v += std::abs(w[t] * u[t]);
  return v;
}

// Offset (dx, dy, dz) of box index t.
template <int Dim> std::array<int, 3> offset(int t) {
  return {t % 3 - 1, (t / 3) % 3 - 1, Dim == 3 ? t / 9 - 1 : 0};
}

// ---------------------------------------------------------------------------------------------
// A patch of cells around one grid row: nx + 2 cells along x (the row's n = nx cells and one
// ghost on each side), 3 along y (and z in 3-D), with cell values in x-fastest arrays.
template <int Dim> struct Patch {
  using T = TensorLayout<Dim>;
  int nx;
  int ext[3];
  long st[3];
  std::vector<double> u;
  std::vector<std::vector<double>> c;    // cell coefficients, nc arrays (1 for isotropic)
  std::vector<std::vector<double>> dual; // dual-cell means, indexed by the lower cell

  Patch(int n, int nc) : nx(n) {
    ext[0] = n + 2;
    ext[1] = 3;
    ext[2] = Dim == 3 ? 3 : 1;
    st[0] = 1;
    st[1] = ext[0];
    st[2] = static_cast<long>(ext[0]) * ext[1];
    const size_t size = static_cast<size_t>(ext[0]) * ext[1] * ext[2];
    u.assign(size, 0.0);
    c.assign(static_cast<size_t>(nc), std::vector<double>(size, 0.0));
  }
  long idx(int i, int j, int k) const { return i + st[1] * j + st[2] * k; }
  // Row cell m (0..nx-1): patch cell (m + 1, 1, 1) (k = 0 in 2-D).
  long row_cell(int m) const { return idx(m + 1, 1, Dim == 3 ? 1 : 0); }

  void build_dual() {
    constexpr int NQ = 1 << Dim;
    dual.assign(c.size(), std::vector<double>(u.size(), 0.0));
    for (int k = 0; k + (Dim == 3 ? 1 : 0) < ext[2]; ++k)
      for (int j = 0; j + 1 < ext[1]; ++j)
        for (int i = 0; i + 1 < ext[0]; ++i)
          for (size_t q = 0; q < c.size(); ++q) {
            double sum = 0;
            for (int b = 0; b < NQ; ++b)
              sum += c[q][idx(i + (b & 1), j + ((b >> 1) & 1), k + (Dim == 3 ? (b >> 2) : 0))];
            dual[q][idx(i, j, k)] = sum / NQ;
          }
  }

  // Coefficient neighbourhood c[t * nc + q] and u values of the 3^dim box of row cell m.
  void neighbourhood(int m, std::vector<double>& cv, std::vector<double>& uv) const {
    const int nc = static_cast<int>(c.size());
    cv.assign(static_cast<size_t>(T::nb * nc), 0.0);
    uv.assign(static_cast<size_t>(T::nb), 0.0);
    const long p = row_cell(m);
    for (int t = 0; t < T::nb; ++t) {
      const auto o = offset<Dim>(t);
      const long n = p + o[0] * st[0] + o[1] * st[1] + o[2] * st[2];
      uv[t] = u[n];
      for (int q = 0; q < nc; ++q)
        cv[t * nc + q] = c[q][n];
    }
  }
};

template <int Dim> Patch<Dim> random_patch(std::mt19937_64& rng, int nx, bool iso) {
  using T = TensorLayout<Dim>;
  Patch<Dim> p(nx, iso ? 1 : T::nc);
  std::uniform_real_distribution<double> U(-1.0, 1.0), Dpos(0.1, 3.0);
  for (double& v : p.u)
    v = U(rng);
  for (size_t n = 0; n < p.u.size(); ++n) {
    if (iso) {
      p.c[0][n] = Dpos(rng);
      continue;
    }
    const auto s = random_spd<Dim>(rng);
    for (int q = 0; q < T::nc; ++q)
      p.c[q][n] = s[q];
  }
  p.build_dual();
  return p;
}

template <int Dim, DiffusionScheme S> void check_weights_match_direct(unsigned seed) {
  std::mt19937_64 rng(seed);
  const double inv_h[3] = {1 / 0.3, 1 / 0.7, 1 / 0.45};
  constexpr bool iso = S == DiffusionScheme::IsotropicField;
  const int nx = 7;
  for (int trial = 0; trial < 20; ++trial) {
    Patch<Dim> p = random_patch<Dim>(rng, nx, iso);
    const auto& src = S == DiffusionScheme::Tensor ? p.dual : p.c;
    std::vector<const double*> coef;
    for (const auto& a : src)
      coef.push_back(a.data() + p.row_cell(0));
    std::vector<double> out(static_cast<size_t>(nx));
    diffusion_row<Dim, S>(nx, coef.data(), p.st, p.u.data() + p.row_cell(0), inv_h, out.data());
    std::vector<double> cv, uv, w(TensorLayout<Dim>::nb);
    for (int m = 0; m < nx; ++m) {
      p.neighbourhood(m, cv, uv);
      scheme_weights<Dim>(S, cv.data(), inv_h, w.data());
      const double via_w = apply<Dim>(w.data(), uv.data());
      const double scale = abs_apply<Dim>(w.data(), uv.data());
      ASSERT_GT(scale, 0.0);
      EXPECT_NEAR(out[m], via_w, 1e-12 * scale)
          << "dim " << Dim << " scheme " << static_cast<int>(S) << " trial " << trial << " cell "
          << m;
      // The single-cell direct forms agree with the row.
      std::vector<const double*> cq;
      for (const auto& a : src)
        cq.push_back(a.data() + p.row_cell(m));
      const double* up = p.u.data() + p.row_cell(m);
      double direct = 0;
      if constexpr (S == DiffusionScheme::Tensor)
        direct = tensor_divergence<Dim>(up, cq.data(), p.st, inv_h);
      else if constexpr (S == DiffusionScheme::TensorFirstOrder)
        direct = tensor_divergence_first_order<Dim>(up, cq.data(), p.st, inv_h);
      else
        direct = isotropic_divergence<Dim>(up, cq.data(), p.st, inv_h);
      EXPECT_NEAR(direct, out[m], 1e-14 * scale); // the row may be vectorised
    }
  }
}

// Neighbourhood of a tensor field sigma(x) given per offset.
template <int Dim, class F> std::vector<double> tensor_neighbourhood(F sigma_at) {
  using T = TensorLayout<Dim>;
  std::vector<double> cv(static_cast<size_t>(T::nb * T::nc));
  for (int t = 0; t < T::nb; ++t) {
    const std::array<double, 6> s = sigma_at(offset<Dim>(t));
    for (int q = 0; q < T::nc; ++q)
      cv[t * T::nc + q] = s[q];
  }
  return cv;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// (a) weights == direct explicit forms

TEST(DiffusionKernel, TensorWeightsMatchDualCellDivergence2D) {
  check_weights_match_direct<2, DiffusionScheme::Tensor>(11);
}
TEST(DiffusionKernel, TensorWeightsMatchDualCellDivergence3D) {
  check_weights_match_direct<3, DiffusionScheme::Tensor>(12);
}
TEST(DiffusionKernel, FirstOrderWeightsMatchDirect2D) {
  check_weights_match_direct<2, DiffusionScheme::TensorFirstOrder>(13);
}
TEST(DiffusionKernel, FirstOrderWeightsMatchDirect3D) {
  check_weights_match_direct<3, DiffusionScheme::TensorFirstOrder>(14);
}
TEST(DiffusionKernel, IsotropicWeightsMatchDirect2D) {
  check_weights_match_direct<2, DiffusionScheme::IsotropicField>(15);
}
TEST(DiffusionKernel, IsotropicWeightsMatchDirect3D) {
  check_weights_match_direct<3, DiffusionScheme::IsotropicField>(16);
}

// The hand-written 2-D divergence equals the generic dual-cell loop's formula, evaluated
// through the 3-D kernel on a z-invariant field with sigma_xz = sigma_yz = 0 (the z terms
// vanish for u constant along z).
TEST(DiffusionKernel, TensorDivergence2DMatchesGeneric3DOnZInvariantField) {
  std::mt19937_64 rng(21);
  const double inv_h2[3] = {1 / 0.3, 1 / 0.7, 1.0}, inv_h3[3] = {1 / 0.3, 1 / 0.7, 1 / 0.45};
  for (int trial = 0; trial < 10; ++trial) {
    Patch<2> p2 = random_patch<2>(rng, 5, false);
    Patch<3> p3(5, 6);
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 7; ++i) {
          const long n2 = p2.idx(i, j, 0), n3 = p3.idx(i, j, k);
          p3.u[n3] = p2.u[n2];
          p3.c[0][n3] = p2.c[0][n2];
          p3.c[1][n3] = p2.c[1][n2];
          p3.c[2][n3] = 0;
          p3.c[3][n3] = p2.c[2][n2];
          p3.c[4][n3] = 0;
          p3.c[5][n3] = 1.0 + 0.1 * trial;
        }
    p3.build_dual();
    for (int m = 0; m < 5; ++m) {
      std::vector<const double*> c2, c3;
      for (auto& a : p2.dual)
        c2.push_back(a.data() + p2.row_cell(m));
      for (auto& a : p3.dual)
        c3.push_back(a.data() + p3.row_cell(m));
      const double d2 =
          tensor_divergence<2>(p2.u.data() + p2.row_cell(m), c2.data(), p2.st, inv_h2);
      const double d3 =
          tensor_divergence<3>(p3.u.data() + p3.row_cell(m), c3.data(), p3.st, inv_h3);
      EXPECT_NEAR(d2, d3, 1e-12 * (std::abs(d2) + 10.0));
    }
  }
}

// ---------------------------------------------------------------------------------------------
// (b) sigma = D I: D times the 5/7-point Laplacian

template <int Dim> void check_isotropic_tensor() {
  using T = TensorLayout<Dim>;
  const double h[3] = {0.3, 0.7, 0.45}, inv_h[3] = {1 / h[0], 1 / h[1], 1 / h[2]};
  const double D = 0.37;
  std::array<double, 6> s{};
  for (int a = 0; a < Dim; ++a)
    s[T::index(a, a)] = D;
  const auto cv = tensor_neighbourhood<Dim>([&](std::array<int, 3>) { return s; });
  std::vector<double> cd(T::nb, D);
  double lap[27] = {};
  for (int a = 0; a < Dim; ++a) {
    int o[3] = {0, 0, 0};
    for (int sg = -1; sg <= 1; sg += 2) {
      o[a] = sg;
      lap[T::box(o[0], o[1], o[2])] += D / (h[a] * h[a]);
    }
    lap[kCentre<Dim>] -= 2 * D / (h[a] * h[a]);
  }
  double w2[27], w1[27], wi[27];
  tensor_weights<Dim>(cv.data(), inv_h, w2);
  tensor_weights_first_order<Dim>(cv.data(), inv_h, w1);
  isotropic_weights<Dim>(cd.data(), inv_h, wi);
  const double tol = 1e-14 * std::abs(lap[kCentre<Dim>]);
  for (int t = 0; t < T::nb; ++t) {
    EXPECT_NEAR(w2[t], lap[t], tol) << "second order, offset " << t;
    EXPECT_NEAR(w1[t], lap[t], tol) << "first order, offset " << t;
    EXPECT_NEAR(wi[t], lap[t], tol) << "isotropic, offset " << t;
  }
}

TEST(DiffusionKernel, IsotropicTensorGivesFivePointLaplacian) {
  check_isotropic_tensor<2>();
}
TEST(DiffusionKernel, IsotropicTensorGivesSevenPointLaplacian) {
  check_isotropic_tensor<3>();
}

// A diagonal (anisotropic, varying) tensor gives a star stencil: no corner weights.
template <int Dim> void check_diagonal_star() {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> U(0.2, 2.0);
  const double inv_h[3] = {1 / 0.3, 1 / 0.7, 1 / 0.45};
  const auto cv = tensor_neighbourhood<Dim>([&](std::array<int, 3>) {
    std::array<double, 6> s{};
    for (int a = 0; a < Dim; ++a)
      s[T::index(a, a)] = U(rng);
    return s;
  });
  double w[27];
  tensor_weights<Dim>(cv.data(), inv_h, w);
  for (int t = 0; t < T::nb; ++t) {
    const auto o = offset<Dim>(t);
    const int nonzero = (o[0] != 0) + (o[1] != 0) + (o[2] != 0);
    if (nonzero >= 2) {
      EXPECT_NEAR(w[t], 0.0, 1e-13) << "offset " << t;
    } else if (nonzero == 1) {
      EXPECT_GT(w[t], 0.0) << "offset " << t;
    }
  }
}

TEST(DiffusionKernel, DiagonalTensorGivesStar2D) {
  check_diagonal_star<2>();
}
TEST(DiffusionKernel, DiagonalTensorGivesStar3D) {
  check_diagonal_star<3>();
}

// ---------------------------------------------------------------------------------------------
// (c) row sums, n -> -n symmetry of a constant tensor, first order == second order

template <int Dim> void check_row_sums_and_symmetry(unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> Dpos(0.1, 3.0);
  const double inv_h[3] = {1 / 0.3, 1 / 0.7, 1 / 0.45};
  for (int trial = 0; trial < 20; ++trial) {
    // Varying tensor and isotropic field: rows sum to zero.
    const auto cv =
        tensor_neighbourhood<Dim>([&](std::array<int, 3>) { return random_spd<Dim>(rng); });
    std::vector<double> cd(T::nb);
    for (double& v : cd)
      v = Dpos(rng);
    double w2[27], w1[27], wi[27];
    tensor_weights<Dim>(cv.data(), inv_h, w2);
    tensor_weights_first_order<Dim>(cv.data(), inv_h, w1);
    isotropic_weights<Dim>(cd.data(), inv_h, wi);
    for (const double* w : {w2, w1, wi}) {
      double sum = 0, scale = 0;
      for (int t = 0; t < T::nb; ++t)
        sum += w[t], scale += std::abs(w[t]);
      EXPECT_NEAR(sum, 0.0, 1e-14 * scale);
      EXPECT_LT(w[kCentre<Dim>], 0.0);
    }
    // Constant tensor: w(n) = w(-n), and the first-order masks are the same operator.
    const auto s = random_spd<Dim>(rng);
    const auto cc = tensor_neighbourhood<Dim>([&](std::array<int, 3>) { return s; });
    tensor_weights<Dim>(cc.data(), inv_h, w2);
    tensor_weights_first_order<Dim>(cc.data(), inv_h, w1);
    double scale = 0;
    for (int t = 0; t < T::nb; ++t)
      scale = std::max(scale, std::abs(w2[t]));
    for (int t = 0; t < T::nb; ++t) {
      const int mirror = T::nb - 1 - t; // box index of -n
      EXPECT_NEAR(w2[t], w2[mirror], 1e-14 * scale) << "second order, offset " << t;
      EXPECT_NEAR(w1[t], w1[mirror], 1e-14 * scale) << "first order, offset " << t;
      EXPECT_NEAR(w1[t], w2[t], 1e-14 * scale) << "first vs second order, offset " << t;
    }
  }
}

TEST(DiffusionKernel, RowSumsZeroAndConstantTensorSymmetric2D) {
  check_row_sums_and_symmetry<2>(41);
}
TEST(DiffusionKernel, RowSumsZeroAndConstantTensorSymmetric3D) {
  check_row_sums_and_symmetry<3>(42);
}

// ---------------------------------------------------------------------------------------------
// (d) exactness

// Linear u = g.x with sigma(x) = S0 + sum_d x_d G_d: div(sigma grad u) = sum_ab (G_a)_ab g_b,
// exact for the second-order scheme (face fluxes are exact for linear data). The first-order
// masks drop the tensor-gradient terms and give 0.
template <int Dim> void check_linear_exactness(unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const double h[3] = {0.3, 0.7, 0.45}, inv_h[3] = {1 / h[0], 1 / h[1], 1 / h[2]};
  for (int trial = 0; trial < 20; ++trial) {
    const auto S0 = random_spd<Dim>(rng, 1.0);
    std::array<std::array<double, 6>, 3> G{};
    for (int d = 0; d < Dim; ++d)
      for (int q = 0; q < T::nc; ++q)
        G[d][q] = 0.3 * U(rng); // small enough to keep sigma positive definite on the box
    const double g[3] = {U(rng), U(rng), U(rng)}, u0 = U(rng);
    const double x0[3] = {0.2, -0.4, 0.3}; // cell centre
    auto x_of = [&](const std::array<int, 3>& o, int d) { return x0[d] + o[d] * h[d]; };
    const auto cv = tensor_neighbourhood<Dim>([&](std::array<int, 3> o) {
      std::array<double, 6> s = S0;
      for (int d = 0; d < Dim; ++d)
        for (int q = 0; q < T::nc; ++q)
          s[q] += x_of(o, d) * G[d][q];
      EXPECT_TRUE(tensor_positive_definite<Dim>(s.data()));
      return s;
    });
    std::vector<double> uv(T::nb);
    for (int t = 0; t < T::nb; ++t) {
      const auto o = offset<Dim>(t);
      uv[t] = u0;
      for (int d = 0; d < Dim; ++d)
        uv[t] += g[d] * x_of(o, d);
    }
    double exact = 0;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        exact += G[a][T::index(a, b)] * g[b];
    double w[27], w1[27];
    tensor_weights<Dim>(cv.data(), inv_h, w);
    tensor_weights_first_order<Dim>(cv.data(), inv_h, w1);
    const double tol = 1e-13 * abs_apply<Dim>(w, uv.data());
    EXPECT_NEAR(apply<Dim>(w, uv.data()), exact, tol) << "trial " << trial;
    EXPECT_NEAR(apply<Dim>(w1, uv.data()), 0.0, 1e-13 * abs_apply<Dim>(w1, uv.data()));
    // Isotropic field D(x) = D0 + G.x with linear u: div(D grad u) = G.g exactly.
    const double D0 = 2.0, GD[3] = {0.5 * U(rng), 0.5 * U(rng), 0.5 * U(rng)};
    std::vector<double> cd(T::nb);
    for (int t = 0; t < T::nb; ++t) {
      const auto o = offset<Dim>(t);
      cd[t] = D0;
      for (int d = 0; d < Dim; ++d)
        cd[t] += GD[d] * x_of(o, d);
    }
    double wi[27];
    isotropic_weights<Dim>(cd.data(), inv_h, wi);
    double exact_iso = 0;
    for (int d = 0; d < Dim; ++d)
      exact_iso += GD[d] * g[d];
    EXPECT_NEAR(apply<Dim>(wi, uv.data()), exact_iso, 1e-13 * abs_apply<Dim>(wi, uv.data()));
  }
}

TEST(DiffusionKernel, LinearUWithLinearTensorExact2D) {
  check_linear_exactness<2>(51);
}
TEST(DiffusionKernel, LinearUWithLinearTensorExact3D) {
  check_linear_exactness<3>(52);
}

// Quadratic u = x^T Q x / 2 + g.x with a constant tensor: div(sigma grad u) = sum_ab s_ab Q_ab
// for both tensor schemes.
template <int Dim> void check_quadratic_exactness(unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const double h[3] = {0.3, 0.7, 0.45}, inv_h[3] = {1 / h[0], 1 / h[1], 1 / h[2]};
  for (int trial = 0; trial < 20; ++trial) {
    const auto s = random_spd<Dim>(rng);
    double Q[3][3], g[3];
    for (int a = 0; a < 3; ++a) {
      g[a] = U(rng);
      for (int b = 0; b <= a; ++b)
        Q[a][b] = Q[b][a] = U(rng);
    }
    const double x0[3] = {0.7, 0.1, -0.2};
    const auto cv = tensor_neighbourhood<Dim>([&](std::array<int, 3>) { return s; });
    std::vector<double> uv(T::nb);
    for (int t = 0; t < T::nb; ++t) {
      const auto o = offset<Dim>(t);
      double x[3];
      for (int d = 0; d < 3; ++d)
        x[d] = d < Dim ? x0[d] + o[d] * h[d] : 0.0;
      double v = 0;
      for (int a = 0; a < Dim; ++a) {
        v += g[a] * x[a];
        for (int b = 0; b < Dim; ++b)
          v += 0.5 * x[a] * Q[a][b] * x[b];
      }
      uv[t] = v;
    }
    double exact = 0;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b)
        exact += component<Dim>(s.data(), a, b) * Q[a][b];
    double w2[27], w1[27];
    tensor_weights<Dim>(cv.data(), inv_h, w2);
    tensor_weights_first_order<Dim>(cv.data(), inv_h, w1);
    EXPECT_NEAR(apply<Dim>(w2, uv.data()), exact, 1e-12 * abs_apply<Dim>(w2, uv.data()));
    EXPECT_NEAR(apply<Dim>(w1, uv.data()), exact, 1e-12 * abs_apply<Dim>(w1, uv.data()));
  }
}

TEST(DiffusionKernel, QuadraticUWithConstantTensorExact2D) {
  check_quadratic_exactness<2>(61);
}
TEST(DiffusionKernel, QuadraticUWithConstantTensorExact3D) {
  check_quadratic_exactness<3>(62);
}

// The first-order masks discretise sigma:grad grad u (non-divergence form, the cell's own
// tensor): quadratic u = x^T Q x / 2 + g.x with a linearly varying tensor sigma(x) = S0 +
// sum_d x_d G_d gives sigma(x0):Q exactly, which differs from div(sigma grad u) by the omitted
// tensor-gradient terms (div sigma).grad u = sum_ab (G_a)_ab (Q x0 + g)_b.
template <int Dim> void check_first_order_non_divergence(unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const double h[3] = {0.3, 0.7, 0.45}, inv_h[3] = {1 / h[0], 1 / h[1], 1 / h[2]};
  for (int trial = 0; trial < 20; ++trial) {
    const auto S0 = random_spd<Dim>(rng, 1.0);
    std::array<std::array<double, 6>, 3> G{};
    for (int d = 0; d < Dim; ++d)
      for (int q = 0; q < T::nc; ++q)
        G[d][q] = 0.3 * U(rng);
    double Q[3][3], g[3];
    for (int a = 0; a < 3; ++a) {
      g[a] = U(rng);
      for (int b = 0; b <= a; ++b)
        Q[a][b] = Q[b][a] = U(rng);
    }
    const double x0[3] = {0.2, -0.4, 0.3};
    auto x_of = [&](const std::array<int, 3>& o, int d) { return x0[d] + o[d] * h[d]; };
    const auto cv = tensor_neighbourhood<Dim>([&](std::array<int, 3> o) {
      std::array<double, 6> s = S0;
      for (int d = 0; d < Dim; ++d)
        for (int q = 0; q < T::nc; ++q)
          s[q] += x_of(o, d) * G[d][q];
      return s;
    });
    std::vector<double> uv(T::nb);
    for (int t = 0; t < T::nb; ++t) {
      const auto o = offset<Dim>(t);
      double v = 0;
      for (int a = 0; a < Dim; ++a) {
        v += g[a] * x_of(o, a);
        for (int b = 0; b < Dim; ++b)
          v += 0.5 * x_of(o, a) * Q[a][b] * x_of(o, b);
      }
      uv[t] = v;
    }
    const double* s0 = cv.data() + kCentre<Dim> * T::nc; // sigma(x0)
    double nondiv = 0, omitted = 0;
    for (int a = 0; a < Dim; ++a)
      for (int b = 0; b < Dim; ++b) {
        nondiv += component<Dim>(s0, a, b) * Q[a][b];
        double grad_b = g[b];
        for (int e = 0; e < Dim; ++e)
          grad_b += Q[b][e] * x0[e];
        omitted += G[a][T::index(a, b)] * grad_b;
      }
    double w1[27];
    tensor_weights_first_order<Dim>(cv.data(), inv_h, w1);
    const double scale = abs_apply<Dim>(w1, uv.data());
    EXPECT_NEAR(apply<Dim>(w1, uv.data()), nondiv, 1e-12 * scale) << "trial " << trial;
    // ... and so misses div(sigma grad u) = nondiv + omitted by the omitted terms.
    EXPECT_GT(std::abs(apply<Dim>(w1, uv.data()) - (nondiv + omitted)), 1e3 * 1e-12 * scale)
        << "trial " << trial;
  }
}

TEST(DiffusionKernel, FirstOrderMasksAreNonDivergenceForm2D) {
  check_first_order_non_divergence<2>(63);
}
TEST(DiffusionKernel, FirstOrderMasksAreNonDivergenceForm3D) {
  check_first_order_non_divergence<3>(64);
}

// ---------------------------------------------------------------------------------------------
// (e) energy form on a periodic grid

template <int Dim> void check_energy_form(const std::array<int, 3>& n, unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  const double h[3] = {0.3, 0.5, 0.4}, inv_h[3] = {1 / h[0], 1 / h[1], 1 / h[2]};
  const int N = n[0] * n[1] * (Dim == 3 ? n[2] : 1);
  auto cell = [&](int i, int j, int k) {
    i = (i % n[0] + n[0]) % n[0];
    j = (j % n[1] + n[1]) % n[1];
    k = Dim == 3 ? (k % n[2] + n[2]) % n[2] : 0;
    return i + n[0] * (j + n[1] * k);
  };
  // Strongly anisotropic random cell tensors.
  std::vector<std::array<double, 6>> sig(static_cast<size_t>(N));
  double lmax = 0;
  for (auto& s : sig) {
    s = random_spd<Dim>(rng, 0.01);
    lmax = std::max(lmax, tensor_max_eigenvalue<Dim>(s.data()));
  }
  std::vector<double> L(static_cast<size_t>(N) * N, 0.0), Li(static_cast<size_t>(N) * N, 0.0);
  std::vector<double> cv(T::nb * T::nc), w(T::nb);
  for (int k = 0; k < (Dim == 3 ? n[2] : 1); ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int p = cell(i, j, k);
        for (int t = 0; t < T::nb; ++t) {
          const auto o = offset<Dim>(t);
          for (int q = 0; q < T::nc; ++q)
            cv[t * T::nc + q] = sig[cell(i + o[0], j + o[1], k + o[2])][q];
        }
        tensor_weights<Dim>(cv.data(), inv_h, w.data());
        for (int t = 0; t < T::nb; ++t) {
          const auto o = offset<Dim>(t);
          L[static_cast<size_t>(p) * N + cell(i + o[0], j + o[1], k + o[2])] += w[t];
        }
        for (int a = 0; a < Dim; ++a) {
          int o[3] = {0, 0, 0};
          for (int sg = -1; sg <= 1; sg += 2) {
            o[a] = sg;
            Li[static_cast<size_t>(p) * N + cell(i + o[0], j + o[1], k + o[2])] +=
                inv_h[a] * inv_h[a];
          }
          Li[static_cast<size_t>(p) * N + p] -= 2 * inv_h[a] * inv_h[a];
        }
      }
  double scale = 0;
  for (double v : L)
    scale = std::max(scale, std::abs(v));
  // Symmetric, rows and columns sum to zero (conservative).
  for (int p = 0; p < N; ++p) {
    double row = 0, col = 0;
    for (int q = 0; q < N; ++q) {
      EXPECT_NEAR(L[static_cast<size_t>(p) * N + q], L[static_cast<size_t>(q) * N + p],
                  1e-13 * scale)
          << p << "," << q;
      row += L[static_cast<size_t>(p) * N + q];
      col += L[static_cast<size_t>(q) * N + p];
    }
    EXPECT_NEAR(row, 0.0, 1e-13 * scale);
    EXPECT_NEAR(col, 0.0, 1e-13 * scale);
  }
  // Spectrum in [-lambda_max rho(L_iso), 0], rho(L_iso) <= sum 4/h^2.
  double rho = 0;
  for (int d = 0; d < Dim; ++d)
    rho += 4 * inv_h[d] * inv_h[d];
  // Symmetrise away round-off before the eigen-solve.
  std::vector<double> Ls(L.size());
  for (int p = 0; p < N; ++p)
    for (int q = 0; q < N; ++q)
      Ls[static_cast<size_t>(p) * N + q] =
          0.5 * (L[static_cast<size_t>(p) * N + q] + L[static_cast<size_t>(q) * N + p]);
  const auto ev = jacobi_eigenvalues(Ls, N);
  EXPECT_LE(ev.back(), 1e-11 * scale);
  EXPECT_NEAR(ev.back(), 0.0, 1e-11 * scale); // constants are in the kernel
  EXPECT_GE(ev.front(), -lmax * rho * (1 + 1e-12));
  EXPECT_LT(ev.front(), 0.0);
  // Rayleigh bound on random vectors: 0 >= u^T L u >= lambda_max u^T L_iso u.
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<double> u(static_cast<size_t>(N));
  for (int trial = 0; trial < 200; ++trial) {
    for (double& v : u)
      v = U(rng);
    if (trial % 2) // smooth-ish vectors too
      for (int p = 0; p < N; ++p)
        u[p] = std::sin(0.7 * p + trial) + 0.1 * u[p];
    double uLu = 0, uLiu = 0, norm = 0;
    for (int p = 0; p < N; ++p) {
      norm += u[p] * u[p];
      for (int q = 0; q < N; ++q) {
        uLu += u[p] * L[static_cast<size_t>(p) * N + q] * u[q];
        uLiu += u[p] * Li[static_cast<size_t>(p) * N + q] * u[q];
      }
    }
    const double tol = 1e-12 * scale * norm;
    EXPECT_LE(uLu, tol) << "trial " << trial;
    EXPECT_GE(uLu, lmax * uLiu - tol) << "trial " << trial;
  }
}

TEST(DiffusionKernel, EnergyFormSymmetricNegativeSemiDefinite2D) {
  check_energy_form<2>({6, 5, 1}, 71);
}
TEST(DiffusionKernel, EnergyFormSymmetricNegativeSemiDefinite3D) {
  check_energy_form<3>({4, 4, 3}, 72);
}

// ---------------------------------------------------------------------------------------------
// Eigenvalue and definiteness helpers.

template <int Dim> void check_max_eigenvalue(unsigned seed) {
  using T = TensorLayout<Dim>;
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < 200; ++trial) {
    auto s = random_spd<Dim>(rng, 0.0);
    if (trial % 3 == 0) // shift: indefinite or negative definite
      for (int a = 0; a < Dim; ++a)
        s[T::index(a, a)] -= 1.0;
    const auto ev = jacobi_eigenvalues(full<Dim>(s.data()), Dim);
    EXPECT_NEAR(tensor_max_eigenvalue<Dim>(s.data()), ev.back(),
                1e-12 * (std::abs(ev.front()) + std::abs(ev.back())));
    const bool pd = ev.front() > 1e-9 * std::abs(ev.back());
    const bool nd_or_indef = ev.front() < -1e-9 * std::abs(ev.back());
    if (pd) {
      EXPECT_TRUE(tensor_positive_definite<Dim>(s.data()));
    } else if (nd_or_indef) {
      EXPECT_FALSE(tensor_positive_definite<Dim>(s.data()));
    }
  }
  // Isotropic and repeated eigenvalues.
  std::array<double, 6> iso{};
  for (int a = 0; a < Dim; ++a)
    iso[T::index(a, a)] = 2.5;
  EXPECT_NEAR(tensor_max_eigenvalue<Dim>(iso.data()), 2.5, 1e-14);
}

TEST(DiffusionKernel, MaxEigenvalueAndDefiniteness2D) {
  check_max_eigenvalue<2>(81);
}
TEST(DiffusionKernel, MaxEigenvalueAndDefiniteness3D) {
  check_max_eigenvalue<3>(82);
}
