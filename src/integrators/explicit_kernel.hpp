// Fused explicit Euler sweep over one row of cells (pure kernel: no PETSc, MPI, allocation).
//
// For each cell i of the row and each species s:
//   lap_s   = sum_t w_t u_s(i + off_t)                 (stencil term 0 is the cell itself)
//   out_s   = max( u_s + dt (D_s lap_s + R_s(u; p)),  floor_s )
// floor_s is 0 when negative concentrations are clamped and -inf otherwise (branch-free).
// Parameters are either scalars (FieldParams = false: one value for the whole grid, kept in
// registers) or rows of per-cell values (FieldParams = true). The loop over i carries
// `GCC ivdep` (rows never alias): the model's rates() inline into it and GCC vectorises it
// (build with -DMORPHOGEN_VEC_REPORT=ON to see "loop vectorized" for explicit_kernel.hpp).
// (`omp simd` is not used: it turns the small per-cell arrays into "simd arrays" and GCC 12
// then refuses to vectorise.)
#pragma once

namespace morphogen {

struct ExplicitRow {
  int n = 0; // cells in the row
  const double* const* src =
      nullptr;                   // [nspecies * nterms]: src[s*NT+t][i] = u_s at neighbour t of i
  const double* w = nullptr;     // [nterms] stencil weights (include 1/h^2)
  const double* D = nullptr;     // [nspecies] diffusion coefficients
  const double* floor = nullptr; // [nspecies] lower bound (0 or -inf)
  const double* const* prow = nullptr; // [nparams] per-cell parameter rows (field mode)
  const double* pconst = nullptr;      // [nparams] parameter scalars (scalar mode)
  double dt = 0;
  double* const* dst = nullptr; // [nspecies] output rows
};

template <class M, int NT, bool FieldParams> inline void explicit_row(const ExplicitRow& a) {
  constexpr int NS = M::nspecies;
  constexpr int NP = M::nparams;
  const double* __restrict__ src[NS * NT];
  double* __restrict__ dst[NS];
  double w[NT], D[NS], floor[NS], pc[NP > 0 ? NP : 1];
  const double* __restrict__ prow[NP > 0 ? NP : 1];
  for (int q = 0; q < NS * NT; ++q)
    src[q] = a.src[q];
  for (int t = 0; t < NT; ++t)
    w[t] = a.w[t];
  for (int s = 0; s < NS; ++s) {
    dst[s] = a.dst[s];
    D[s] = a.D[s];
    floor[s] = a.floor[s];
  }
  for (int q = 0; q < NP; ++q) {
    if constexpr (FieldParams)
      prow[q] = a.prow[q];
    else
      pc[q] = a.pconst[q];
  }
  const double dt = a.dt;
  const int n = a.n;
#pragma GCC ivdep
  for (int i = 0; i < n; ++i) {
    double u[NS], r[NS], p[NP > 0 ? NP : 1];
    for (int q = 0; q < NP; ++q) {
      if constexpr (FieldParams)
        p[q] = prow[q][i];
      else
        p[q] = pc[q];
    }
    for (int s = 0; s < NS; ++s)
      u[s] = src[s * NT][i];
    M::rates(u, p, r);
    for (int s = 0; s < NS; ++s) {
      double lap = w[0] * u[s];
      for (int t = 1; t < NT; ++t)
        lap += w[t] * src[s * NT + t][i];
      const double v = u[s] + dt * (D[s] * lap + r[s]);
      dst[s][i] = v > floor[s] ? v : floor[s];
    }
  }
}

} // namespace morphogen
