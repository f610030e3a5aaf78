// Row kernels of the slow-axis tridiagonal solve (pure kernels: no PETSc, MPI, allocation).
// A row is n lanes (spectral entries of one plane, real and imaginary parts as separate lanes);
// the coefficients are per lane. The system along the slow axis, per lane:
//   a x_{j-1} + b_j x_j + g x_{j+1} = f_j.
// Thomas elimination of an interior block (rows 1 .. n_i, no pivoting: the matrices here are
// strictly diagonally dominant): forward  y_1 = f_1 inv_1,  y_j = (f_j - a y_{j-1}) inv_j,
// backward  x_j = y_j - gp_j x_{j+1},  with inv_j = 1 / (b - a gp_{j-1}), gp_j = g inv_j.
#pragma once

namespace morphogen {

// The explicit (Crank-Nicolson) product, row by row along the slow axis, in place:
//   cur <- s0 cur + s1 ((a prev + b cur) + g next),
// with a prev carried: pa holds a prev on entry (tri_times_row for the first row) and a cur on
// return, which the next row needs (so a raw row never has to be copied aside).
inline void tri_multiply_row_carry(int n, double s0, double s1, const double* a, const double* b,
                                   const double* g, double* pa, const double* next, double* cur) {
  for (int l = 0; l < n; ++l) {
    const double c = cur[l];
    const double out = s0 * c + s1 * ((pa[l] + b[l] * c) + g[l] * next[l]);
    pa[l] = a[l] * c;
    cur[l] = out;
  }
}

// out = a x (the first carried products a prev of tri_multiply_row_carry).
inline void tri_times_row(int n, const double* a, const double* x, double* out) {
  for (int l = 0; l < n; ++l)
    out[l] = a[l] * x[l];
}

// Forward elimination step: cur = (cur - a prev) inv (prev null: the first row, cur = cur inv).
inline void tri_forward_row(int n, const double* a, const double* inv, const double* prev,
                            double* cur) {
  if (!prev) {
    for (int l = 0; l < n; ++l)
      cur[l] *= inv[l];
    return;
  }
  for (int l = 0; l < n; ++l)
    cur[l] = (cur[l] - a[l] * prev[l]) * inv[l];
}

// Back substitution step: out = cur - gp next (out may alias cur).
inline void tri_backward_row(int n, const double* gp, const double* next, const double* cur,
                             double* out) {
  for (int l = 0; l < n; ++l)
    out[l] = cur[l] - gp[l] * next[l];
}

// cur *= s.
inline void tri_scale_row(int n, double s, double* cur) {
  for (int l = 0; l < n; ++l)
    cur[l] *= s;
}

// The interior's answer from its particular solution y and the block's end values:
// cur = y - (a F p + g E q).
inline void tri_spike_row(int n, const double* a, const double* g, const double* F, const double* E,
                          const double* p, const double* q, double* cur) {
  for (int l = 0; l < n; ++l)
    cur[l] -= a[l] * F[l] * p[l] + g[l] * E[l] * q[l];
}

// One term of the block ends from the reduced inverse: F += rf gk, E += re gk.
inline void tri_reduced_row(int n, const double* rf, const double* re, const double* gk, double* F,
                            double* E) {
  for (int l = 0; l < n; ++l) {
    F[l] += rf[l] * gk[l];
    E[l] += re[l] * gk[l];
  }
}

} // namespace morphogen
