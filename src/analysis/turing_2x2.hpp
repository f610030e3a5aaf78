// Closed-form Turing analysis of a two-species reaction-diffusion system (the fast path of
// `morphogen screen`, sweep/screen_classify.hpp). For the Jacobian J = [[a, b], [c, d]] at a
// homogeneous steady state and diffusion D = (D0, D1), a mode of wavenumber k grows with the
// eigenvalues of A(q) = J - q diag(D), q = k^2 >= 0, the continuous Laplacian's symbol:
//
//   trace T(q) = T0 - S q,  det Delta(q) = P q^2 - h q + Delta0,
//   S = D0 + D1, P = D0 D1, h = a D1 + d D0, T0 = a + d, Delta0 = a d - b c,
//   sigma(q) = T/2 + sqrt(T^2/4 - Delta) (real), T/2 (complex pair).
//
// With tol = zero_tol * ||J||_inf (as analysis/linear_stability.hpp): stable_homogeneous iff
// sigma(0) < -tol. Then T(q) < 0 for every q, so sigma(q) > 0 needs Delta(q) < 0 (real
// eigenvalues), i.e. h > 0 and h^2 > 4 P Delta0. At a maximum of the larger eigenvalue lambda,
// implicit differentiation of lambda^2 - T lambda + Delta = 0 gives lambda = Delta'/T' =
// (h - 2 P q) / S; substituted back, q solves
//
//   -P (D0 - D1)^2 q^2 + 2 P (S T0 - 2 h) q + (h^2 - S T0 h + S^2 Delta0) = 0,
//
// whose positive roots are the candidates (sigma evaluated directly at each, the larger wins;
// a golden-section search on the band Delta(q) < 0 is the fallback should round-off leave no
// candidate with sigma > 0). turing_unstable iff stable_homogeneous and the maximum sigma > tol.
// Equal D (S^2 = 4 P): sigma(q) = sigma(0) - D q, never Turing. A zero D0 or D1 is not handled
// here (the growth may rise up to k = infinity): `handled` is false, use analyse_jacobian.
// Pure: no allocation, MPI or PETSc; about 100 flops per call.
#pragma once

namespace morphogen::analysis {

struct Turing2x2 {
  bool handled = false; // false: a zero or negative D; use the general analysis
  double tol = 0;
  double growth0 = 0; // sigma(0)
  bool stable_homogeneous = false;
  bool turing_unstable = false;
  double q_fastest = 0;      // k_fastest^2 (0 unless turing_unstable)
  double growth_fastest = 0; // sigma(q_fastest) (growth0 unless turing_unstable)
};

// J row-major (J[1] = dR_0/du_1), D[2]; zero_tol as StabilityOptions::zero_tol.
Turing2x2 turing_2x2(const double* J, const double* D, double zero_tol = 1e-9);

// sigma(q) of the 2x2 system (the larger real part of the eigenvalues of J - q diag(D)).
double growth_2x2(const double* J, const double* D, double q);

} // namespace morphogen::analysis
