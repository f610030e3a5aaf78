// Linear (Turing / Hopf) stability of a homogeneous steady state u* of
//
//   du_s/dt = D_s lap u_s + R_s(u; p),   s = 0..N-1 (N <= 64).
//
// A perturbation e exp(i k.x + lambda t) grows or decays with lambda an eigenvalue of
//
//   A(q) = J - q diag(D),   J[s*N+r] = dR_s/du_r (u*),
//
// where q >= 0 is minus the symbol of the Laplacian at wave vector k:
//   continuous:   q = |k|^2
//   5pt, 7pt:     q = sum_d (4 / h_d^2) sin^2(k_d h_d / 2)
//   9pt:          q = (20 - 8 (cos t_x + cos t_y) - 4 cos t_x cos t_y) / (6 h^2),  t_d = k_d h
// (computed from the stencil weights of grid/stencil.hpp, so it is the simulated operator).
// The growth rate of k is sigma(k) = max Re lambda(A(q(k))); with dt > 0 it is instead the rate
// of the forward Euler map u <- (I + dt A) u, ln|1 + dt lambda| / dt (what the explicit
// integrator does). The dispersion curve is sampled on k in [0, k_max] along a direction and its
// maximum refined by golden-section search (ties within round-off go to the smaller k, so a
// curve that is flat or falls from k = 0 reports k_fastest = 0). Classification, with the rates
// above (Re lambda, or the Euler rate when dt > 0) and tol = zero_tol * ||J||_inf:
//   stable_homogeneous  every Re lambda(A(0)) < -tol
//   hopf                A(0) has a complex pair (|Im| > tol) with Re > tol
//   turing_unstable     stable_homogeneous and max_{k>0} sigma(k) > tol
//   marginal            |max_k sigma(k)| <= tol (on a Turing or Hopf threshold)
//   oscillatory_fastest the fastest k > 0 has |Im lambda| > tol (wave instability)
// Eigenvalues: closed form for N = 2; otherwise LAPACK's dgeev (Debian's liblapack).
// Pure computation: no MPI, no PETSc objects; bad input (sizes, unknown stencil) throws
// UserError.
//
// Per-species (anisotropic) operators: with StabilityOptions::operators, species s diffuses by
// its own constant-coefficient stencil L_s (weights w_t at integer offsets off_t, the diffusion
// coefficient and 1/h^2 folded in), and
//
//   A(k) = J - diag(q_0(k), ..., q_{N-1}(k)),   q_s(k) = -sum_t w_t cos(k . (off_t * h)),
//
// (e.g. a tensor sigma on a 3x3 box: q_s = sigma11 4 sin^2(kx hx/2)/hx^2 + sigma22 4 sin^2(ky hy/2)
// /hy^2 + 2 sigma12 sin(kx hx) sin(ky hy)/(hx hy)). The growth rate then depends on the direction
// of k, not only on |k|. In 2-D the analysis samples `directions` directions in [0, pi), refines
// the best one (golden section on the angle) and analyses the curve, k_fastest and the band along
// the fastest direction (ties within round-off keep opt.direction, so operators D_s * (grid
// stencil) reproduce the results without operators); this costs ~(directions + 45) curves. Note
// that with ONE tensor shared by all species (sigma_s = D_s Sigma) the maximum growth is the same
// in every direction (sigma depends on k only through k^T Sigma k; only the fastest |k| varies, ~
// 1/sqrt(e^T Sigma e)), so the direction is then a tie and stays opt.direction; it is determined
// when the species' tensors differ (in 2 x 2 activator-inhibitor kinetics: the direction maximising
// e^T S_b e / e^T S_a e).
#pragma once

#include "grid/grid.hpp"
#include "models/model_info.hpp"

#include <array>
#include <complex>
#include <optional>
#include <string>
#include <vector>

namespace morphogen::analysis {

// A structured grid as the analysis needs it: spacing and cells per axis, the Laplacian
// stencil ("5pt"/"9pt" in 2-D, "7pt" in 3-D) and per axis periodic (modes 2 pi m / L,
// 0 <= m <= n/2) or zero-flux (cosine modes pi m / L, 0 <= m < n). L_d = n_d h_d.
struct DiscreteGrid {
  int dim = 2;
  std::array<double, 3> h{1, 1, 1};
  std::array<long long, 3> n{0, 0, 0}; // needed only for the allowed modes
  std::array<bool, 3> periodic{true, true, true};
  std::string stencil = "5pt";
};

// The analysis grid of a run: spacing, cells and stencil; periodic axes as such, zero-flux and
// Dirichlet axes as zero-flux (Dirichlet's sine modes have the same k = pi m / L but m >= 1;
// and its boundary values generally differ from u*, so the analysis is only indicative there).
DiscreteGrid discrete_grid(const GridSpec& spec, const std::string& stencil);

// The discrete diffusion operator of one species as pure data: (L u)(x) = sum_t w[t] u(x + off[t]
// * h), the diffusion coefficient (or tensor) and the spacings already in the weights. Must be
// symmetric (the weight at -off equals that at off, to 1e-12 max |w|) and conserve mass (sum w =
// 0, to 1e-12 sum |w|); offsets along axes >= the grid's dim must be 0. Empty: no diffusion.
struct SpeciesOperator {
  std::vector<std::array<int, 3>> off;
  std::vector<double> w;
};

// q_s(k) = -sum_t w_t cos(k . (off_t * h)) (h: the grid's spacings).
double operator_q(const SpeciesOperator& op, const std::array<double, 3>& h,
                  const std::array<double, 3>& k);

struct StabilityOptions {
  std::optional<DiscreteGrid> grid; // none: the continuous Laplacian, q = |k|^2
  // Direction of k for the curve (grid symbols and operators; with operators in 2-D, the
  // fastest direction found replaces it unless `directions` is 0 or it ties).
  std::array<double, 3> direction{1, 0, 0};
  // Per-species operators (empty: D and the grid's stencil / the continuous Laplacian). When
  // given: one per species, opt.grid is required (its dim and spacings; its stencil is unused),
  // D is recorded but not used.
  std::vector<SpeciesOperator> operators;
  int directions = 180;   // operators in 2-D: directions sampled in [0, pi) for the fastest one;
                          // 0: analyse along opt.direction only
  double k_max = 0;       // 0: the grid's Nyquist pi/h along direction, or, continuous,
                          //    3 sqrt(||J||_inf / min positive D) (a few times the fastest k)
  int samples = 1024;     // sampled points of the dispersion curve on [0, k_max]
  double k_tol = 1e-10;   // golden-section / bisection tolerance, relative to k_max
  double dt = 0;          // > 0: rates of the forward Euler step, ln|1 + dt lambda| / dt
  double zero_tol = 1e-9; // relative to ||J||_inf: below it a rate counts as zero
  std::vector<double> u_star;       // analyse this state instead of the model's steady_state
  bool general_eigensolver = false; // the general path even for N = 2 (used by the tests)
};

struct DispersionPoint {
  double k;         // |k|
  double growth;    // sigma(k)
  double frequency; // Im of the eigenvalue that attains sigma (>= 0)
};

struct StabilityResult {
  int nspecies = 0;
  bool has_steady_state = false;
  std::vector<double> u_star;    // the state analysed
  std::vector<double> jacobian;  // J at u_star, N*N row-major
  std::vector<double> diffusion; // D
  std::optional<DiscreteGrid> grid;
  std::vector<SpeciesOperator> operators; // as given (empty: D and the grid's stencil)
  double dt = 0;
  bool general_eigensolver = false;
  double tol = 0; // zero_tol * ||J||_inf

  std::vector<std::complex<double>> eigen0; // eigenvalues of J (k = 0)
  double growth0 = 0;                       // sigma(0)
  bool stable_homogeneous = false;
  bool hopf = false;
  bool turing_unstable = false;
  bool marginal = false;
  bool oscillatory_fastest = false;

  // The direction of the curve, k_fastest and the band (unit vector): opt.direction, or with
  // operators in 2-D the fastest direction found. direction_fastest is its angle from the x axis
  // in the x-y plane, in [0, pi); k_vector_fastest = k_fastest * direction.
  std::array<double, 3> direction{1, 0, 0};
  double direction_fastest = 0;
  std::array<double, 3> k_vector_fastest{0, 0, 0};
  double k_fastest = 0; // argmax over [0, k_max] of sigma (0 when k = 0 grows fastest)
  double growth_fastest = 0;
  double frequency_fastest = 0;
  double wavelength_fastest = 0; // 2 pi / k_fastest (infinity for k_fastest = 0)
  bool has_band = false;         // sigma > tol on [k_lo, k_hi], the interval around k_fastest
  double k_lo = 0, k_hi = 0;
  bool band_open = false; // the band reaches k_max (sigma still positive there)
  double k_max = 0;
  std::vector<DispersionPoint> curve; // the samples along `direction`, k ascending
};

// The fastest-growing non-uniform mode of a finite grid (what a simulation shows).
struct AllowedMode {
  std::array<long long, 3> m{0, 0, 0}; // mode numbers per axis (m_d >= 0, but see below)
  std::array<double, 3> k{0, 0, 0};    // wave vector components (signs as m)
  double k_abs = 0;
  double q = 0; // the Laplacian symbol (NaN with per-species operators: no single q)
  double growth = 0, frequency = 0;
  double wavelength = 0; // 2 pi / |k|
  long long scanned = 0; // number of modes examined
};

// Eigenvalues of the row-major n x n matrix A, 1 <= n <= 64 (closed form for n = 2 unless
// general, LAPACK dgeev otherwise). Returns false for non-finite input or a failed QR.
bool eigenvalues(int n, const double* A, std::complex<double>* out, bool general = false);

// q(k) = -symbol of the grid's Laplacian at wave vector k (|k|^2 without a grid).
double laplacian_q(const DiscreteGrid* grid, const std::array<double, 3>& k);

// Analysis of a given Jacobian J (N*N, row-major) at a steady state with diffusion D.
StabilityResult analyse_jacobian(int n, const double* J, const double* D,
                                 const StabilityOptions& opt = {});

// Analysis of a model: params has entry.nparams values, D entry.nspecies. The state is
// opt.u_star if given, else entry.steady_state (has_steady_state false if it reports none).
StabilityResult analyse(const ModelInfo& entry, const std::vector<double>& params,
                        const std::vector<double>& D, const StabilityOptions& opt = {});

std::vector<double> default_params(const ModelInfo& entry);
std::vector<double> default_diffusion(const ModelInfo& entry);

// sigma and Im lambda of q for an analysed state (uses r's J, D, dt, eigensolver choice).
// Isotropic case only (A = J - q diag(D)); throws if r has per-species operators.
DispersionPoint growth_at_q(const StabilityResult& r, double q);

// sigma and Im lambda at the wave vector k: with r's operators (and r.grid's spacings) if any,
// else q = laplacian_q(r.grid, k) and D. DispersionPoint::k is |k|.
DispersionPoint growth_at_k(const StabilityResult& r, const std::array<double, 3>& k);

// Wavenumbers of axis `axis` of a grid: 2 pi m / L (periodic, m = 0..n/2) or pi m / L
// (zero-flux, m = 0..n-1).
std::vector<double> allowed_wavenumbers(const DiscreteGrid& grid, int axis);

// The fastest-growing allowed mode with k != 0 over all mode vectors of the grid (every
// n[d] >= 1; uses the grid's stencil symbol, or r's operators, whose weights must be those of
// this grid's spacings). Ties go to the mode scanned first. Cost: one small eigenproblem per
// mode with m_d >= 0, (n/2 + 1)^dim of them (8192^2: ~1 s; with a sign scan, below, up to
// 2^(dim-1) times that).
// An operator that is not symmetric under the reflection of each axis (cross terms: a weight at
// (1, 1) differing from that at (1, -1)) has q(kx, ky) != q(kx, -ky): then every mode is also
// scanned with the sign combinations of its components (up to the overall sign, k ~ -k; axes
// with k_d = 0 or at Nyquist, k_d h_d = pi, have one sign), the first axis with a non-trivial
// sign kept positive, and m, k carry the signs. On zero-flux axes such operators do not separate
// into cosine modes, and the mode is the fastest plane wave with those |k_d| (indicative).
AllowedMode fastest_allowed_mode(const StabilityResult& r, const DiscreteGrid& grid);

// Homogeneous steady states R(u) = 0 found by Newton's method from a lattice of starting points
// in [lo_s, hi_s] per species (defaults: |u_s| <= 2 max(1, |init_s|, |model u*_s|)) and from the
// model's own steady_state. A root is accepted when max |R| <= 1e-10 max(1, max |R| over the
// starts); roots closer than 1e-5 (relative) are merged (Newton is only linear at a fold).
// Sorted lexicographically. A search, not a proof: a state outside the box or with a tiny basin
// can be missed.
struct SteadySearch {
  std::vector<double> lo, hi; // per species; empty: the defaults above
  int points = 0; // per species; 0: 65, 17, 9, 7 for 1-4 species, 3 to 8, 2 to 12, else 1
  int max_it = 60;
};
std::vector<std::vector<double>> find_steady_states(const ModelInfo& entry,
                                                    const std::vector<double>& params,
                                                    const SteadySearch& search = {});

// One line for logs, e.g. "Turing-unstable: fastest wavelength 17.8 (k 0.353), growth 0.012;
// unstable band k in [0.21, 0.52]".
std::string summary(const StabilityResult& r);
std::string summary(const AllowedMode& m);

} // namespace morphogen::analysis
