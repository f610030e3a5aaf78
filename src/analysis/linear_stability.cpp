// Linear stability analysis: see linear_stability.hpp for the equations and the contract.
#include "analysis/linear_stability.hpp"

#include "core/user_error.hpp"
#include "grid/stencil.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

// LAPACK (Fortran): eigenvalues of a general real matrix.
extern "C" void dgeev_(const char* jobvl, const char* jobvr, const int* n, double* a,
                       const int* lda, double* wr, double* wi, double* vl, const int* ldvl,
                       double* vr, const int* ldvr, double* work, const int* lwork, int* info);

namespace morphogen::analysis {

namespace {

constexpr int kMaxSpecies = 64;
constexpr double kPi = std::numbers::pi;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

double inf_norm(int n, const double* A) {
  double best = 0;
  for (int s = 0; s < n; ++s) {
    double row = 0;
    for (int r = 0; r < n; ++r)
      row += std::abs(A[s * n + r]);
    best = std::max(best, row);
  }
  return best;
}

double rate_of(std::complex<double> l, double dt) {
  return dt > 0 ? std::log(std::abs(1.0 + dt * l)) / dt : l.real();
}

// sigma(q) and the frequency of the eigenvalue attaining it, for A = J - q diag(D).
struct Dispersion {
  int n = 0;
  const double* J = nullptr;
  const double* D = nullptr;
  double dt = 0;
  bool general = false;

  DispersionPoint at(double q) const {
    double A[kMaxSpecies * kMaxSpecies];
    for (int i = 0; i < n * n; ++i)
      A[i] = J[i];
    for (int s = 0; s < n; ++s)
      A[s * n + s] -= q * D[s];
    return of(A);
  }
  // A = J - diag(qs): per-species symbols.
  DispersionPoint at_species(const double* qs) const {
    double A[kMaxSpecies * kMaxSpecies];
    for (int i = 0; i < n * n; ++i)
      A[i] = J[i];
    for (int s = 0; s < n; ++s)
      A[s * n + s] -= qs[s];
    return of(A);
  }
  DispersionPoint of(const double* A) const {
    std::complex<double> ev[kMaxSpecies];
    DispersionPoint p{0, std::numeric_limits<double>::quiet_NaN(), 0};
    if (!eigenvalues(n, A, ev, general)) return p;
    p.growth = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      const double g = rate_of(ev[i], dt);
      if (g > p.growth || (g == p.growth && std::abs(ev[i].imag()) > p.frequency)) {
        p.growth = g;
        p.frequency = std::abs(ev[i].imag());
      }
    }
    return p;
  }
};

Stencil stencil_of(const DiscreteGrid& g) {
  Stencil st;
  if (g.dim < 2 || g.dim > 3 || !make_stencil(g.stencil, g.dim, g.h.data(), st))
    throw UserError("linear stability: stencil '" + g.stencil + "' is not available in " +
                    std::to_string(g.dim) + "-D with these spacings");
  return st;
}

// -symbol; the stencils are symmetric in every axis, so sum_t w_t cos(k . off_t h).
double q_of(const Stencil& st, const DiscreteGrid& g, const std::array<double, 3>& k) {
  double s = 0;
  for (int t = 0; t < st.nterms; ++t) {
    double phase = 0;
    for (int d = 0; d < g.dim; ++d)
      phase += k[d] * st.off[t][d] * g.h[d];
    s += st.w[t] * std::cos(phase);
  }
  return -s;
}

// -symbol of a species operator; the same arithmetic as q_of (so D_s * stencil weights with D_s a
// power of two give exactly D_s q).
double op_q(const SpeciesOperator& op, int dim, const std::array<double, 3>& h,
            const std::array<double, 3>& k) {
  double s = 0;
  for (size_t t = 0; t < op.w.size(); ++t) {
    double phase = 0;
    for (int d = 0; d < dim; ++d)
      phase += k[d] * op.off[t][d] * h[d];
    s += op.w[t] * std::cos(phase);
  }
  return -s;
}

// Relative tolerance of the symmetry and conservation checks of the operators.
constexpr double kOpTol = 1e-12;

// The weight of `op` at offset o (summed over repeated offsets).
double weight_at(const SpeciesOperator& op, const std::array<int, 3>& o) {
  double w = 0;
  for (size_t t = 0; t < op.w.size(); ++t)
    if (op.off[t] == o) w += op.w[t];
  return w;
}

double max_abs_w(const SpeciesOperator& op) {
  double m = 0;
  for (double w : op.w)
    m = std::max(m, std::abs(w));
  return m;
}

// Throws unless `ops` are n valid operators for a grid of dimension dim (see the header).
void check_operators(const std::vector<SpeciesOperator>& ops, int n, int dim) {
  if (static_cast<int>(ops.size()) != n)
    throw UserError("linear stability: " + std::to_string(ops.size()) + " species operators for " +
                    std::to_string(n) + " species");
  for (int s = 0; s < n; ++s) {
    const SpeciesOperator& op = ops[s];
    const std::string which = "linear stability: the operator of species " + std::to_string(s);
    if (op.off.size() != op.w.size()) throw UserError(which + " has as many offsets as weights");
    double sum = 0, sum_abs = 0;
    for (size_t t = 0; t < op.w.size(); ++t) {
      if (!std::isfinite(op.w[t])) throw UserError(which + " has a non-finite weight");
      for (int d = dim; d < 3; ++d)
        if (op.off[t][d] != 0)
          throw UserError(which + " has an offset along axis " + std::to_string(d) + " of a " +
                          std::to_string(dim) + "-D grid");
      sum += op.w[t];
      sum_abs += std::abs(op.w[t]);
    }
    if (std::abs(sum) > kOpTol * sum_abs)
      throw UserError(which + " does not conserve mass (its weights do not sum to 0)");
    const double wmax = max_abs_w(op);
    for (const auto& o : op.off)
      if (std::abs(weight_at(op, o) - weight_at(op, {-o[0], -o[1], -o[2]})) > kOpTol * wmax)
        throw UserError(which + " is not symmetric (weight at -off differs from that at off)");
  }
}

// Whether some operator differs from its reflection along some axis d < dim (then q(k) is not
// even in each k_d separately, and the sign combinations of k's components must be scanned).
bool needs_sign_scan(const std::vector<SpeciesOperator>& ops, int dim) {
  for (const auto& op : ops) {
    const double wmax = max_abs_w(op);
    for (const auto& o : op.off)
      for (int d = 0; d < dim; ++d) {
        std::array<int, 3> r = o;
        r[d] = -r[d];
        if (std::abs(weight_at(op, o) - weight_at(op, r)) > kOpTol * wmax) return true;
      }
  }
  return false;
}

// Golden-section search for the maximum of f on [a, b].
template <class F> double golden_max(F&& f, double a, double b, double tol) {
  const double r = (std::sqrt(5.0) - 1) / 2;
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = f(c), fd = f(d);
  while (b - a > tol) {
    if (fc >= fd) {
      b = d, d = c, fd = fc;
      c = b - r * (b - a), fc = f(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + r * (b - a), fd = f(d);
    }
  }
  return fc >= fd ? c : d;
}

// A point where f crosses tol between lo (f <= tol) and hi (f > tol).
template <class F> double bisect_edge(F&& f, double lo, double hi, double tol_f, double tol_k) {
  while (std::abs(hi - lo) > tol_k) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > tol_f ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

// Solve the n x n system M x = b in place (partial pivoting); false if singular.
bool solve_small(int n, double* M, double* b) {
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int r = c + 1; r < n; ++r)
      if (std::abs(M[r * n + c]) > std::abs(M[p * n + c])) p = r;
    if (!(std::abs(M[p * n + c]) > 0)) return false;
    if (p != c) {
      for (int j = 0; j < n; ++j)
        std::swap(M[c * n + j], M[p * n + j]);
      std::swap(b[c], b[p]);
    }
    for (int r = c + 1; r < n; ++r) {
      const double f = M[r * n + c] / M[c * n + c];
      for (int j = c; j < n; ++j)
        M[r * n + j] -= f * M[c * n + j];
      b[r] -= f * b[c];
    }
  }
  for (int c = n - 1; c >= 0; --c) {
    for (int j = c + 1; j < n; ++j)
      b[c] -= M[c * n + j] * b[j];
    b[c] /= M[c * n + c];
  }
  return true;
}

double max_abs(const double* x, int n) {
  double m = 0;
  for (int s = 0; s < n; ++s)
    m = std::max(m, std::abs(x[s]));
  return m;
}

} // namespace

bool eigenvalues(int n, const double* A, std::complex<double>* out, bool general) {
  if (n < 1 || n > kMaxSpecies) return false;
  if (n == 1) {
    out[0] = A[0];
    return true;
  }
  if (n == 2 && !general) {
    const double half = 0.5 * (A[0] + A[3]), dh = 0.5 * (A[0] - A[3]);
    const double disc = dh * dh + A[1] * A[2];
    const double r = std::sqrt(std::abs(disc));
    if (disc >= 0) {
      out[0] = half + r, out[1] = half - r;
    } else {
      out[0] = {half, r}, out[1] = {half, -r};
    }
    return true;
  }
  // General path: LAPACK's dgeev (Hessenberg QR; eigenvalues only). The row-major A read as
  // column-major is its transpose, which has the same eigenvalues.
  for (int i = 0; i < n * n; ++i)
    if (!std::isfinite(A[i])) return false;
  std::vector<double> a(A, A + n * n), wr(n), wi(n), work(static_cast<size_t>(8 * n));
  int nn = n, lda = n, ldv = 1, lwork = 8 * n, info = 0;
  char no = 'N';
  double dummy = 0;
  dgeev_(&no, &no, &nn, a.data(), &lda, wr.data(), wi.data(), &dummy, &ldv, &dummy, &ldv,
         work.data(), &lwork, &info);
  if (info != 0) return false;
  for (int i = 0; i < n; ++i)
    out[i] = {wr[i], wi[i]};
  return true;
}

DiscreteGrid discrete_grid(const GridSpec& spec, const std::string& stencil) {
  DiscreteGrid g;
  g.dim = spec.dim;
  g.stencil = stencil;
  for (int d = 0; d < 3; ++d) {
    g.h[d] = d < spec.dim ? spec.h(d) : 1.0;
    g.n[d] = d < spec.dim ? spec.n[d] : 1;
    g.periodic[d] = spec.bc[d] == Boundary::Periodic;
  }
  return g;
}

double laplacian_q(const DiscreteGrid* grid, const std::array<double, 3>& k) {
  if (!grid) return k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
  return q_of(stencil_of(*grid), *grid, k);
}

double operator_q(const SpeciesOperator& op, const std::array<double, 3>& h,
                  const std::array<double, 3>& k) {
  if (op.off.size() != op.w.size())
    throw UserError("linear stability: a species operator needs as many offsets as weights");
  return op_q(op, 3, h, k);
}

DispersionPoint growth_at_q(const StabilityResult& r, double q) {
  if (!r.has_steady_state)
    throw UserError("linear stability: no steady state was analysed (growth_at_q)");
  if (!r.operators.empty())
    throw UserError("linear stability: growth_at_q needs one symbol for all species; with "
                    "per-species operators use growth_at_k");
  const Dispersion disp{r.nspecies, r.jacobian.data(), r.diffusion.data(), r.dt,
                        r.general_eigensolver};
  DispersionPoint p = disp.at(q);
  p.k = std::sqrt(std::max(q, 0.0));
  return p;
}

DispersionPoint growth_at_k(const StabilityResult& r, const std::array<double, 3>& k) {
  if (!r.has_steady_state)
    throw UserError("linear stability: no steady state was analysed (growth_at_k)");
  const Dispersion disp{r.nspecies, r.jacobian.data(), r.diffusion.data(), r.dt,
                        r.general_eigensolver};
  DispersionPoint p;
  if (r.operators.empty()) {
    p = disp.at(laplacian_q(r.grid ? &*r.grid : nullptr, k));
  } else {
    if (!r.grid) throw UserError("linear stability: species operators need a grid (growth_at_k)");
    double qs[kMaxSpecies];
    for (int s = 0; s < r.nspecies; ++s)
      qs[s] = op_q(r.operators[s], r.grid->dim, r.grid->h, k);
    p = disp.at_species(qs);
  }
  p.k = std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
  return p;
}

StabilityResult analyse_jacobian(int n, const double* J, const double* D,
                                 const StabilityOptions& opt) {
  if (n < 1 || n > kMaxSpecies)
    throw UserError("linear stability: " + std::to_string(n) + " species (1 to " +
                    std::to_string(kMaxSpecies) + " supported)");
  if (opt.samples < 3) throw UserError("linear stability: samples must be at least 3");
  for (int s = 0; s < n; ++s)
    if (!(D[s] >= 0) || !std::isfinite(D[s]))
      throw UserError("linear stability: diffusion coefficients must be finite and >= 0");
  StabilityResult r;
  r.nspecies = n;
  r.has_steady_state = true;
  r.jacobian.assign(J, J + n * n);
  r.diffusion.assign(D, D + n);
  r.grid = opt.grid;
  r.dt = opt.dt;
  r.general_eigensolver = opt.general_eigensolver;
  const double scale = inf_norm(n, J);
  r.tol = opt.zero_tol * scale;

  // k = 0: the kinetics alone.
  r.eigen0.resize(n);
  if (!eigenvalues(n, J, r.eigen0.data(), opt.general_eigensolver))
    throw UserError("linear stability: the eigenvalue computation failed (non-finite Jacobian?)");
  r.growth0 = -std::numeric_limits<double>::infinity();
  for (const auto& l : r.eigen0) {
    const double g = rate_of(l, opt.dt);
    r.growth0 = std::max(r.growth0, g);
    if (std::abs(l.imag()) > r.tol && g > r.tol) r.hopf = true;
  }
  r.stable_homogeneous = r.growth0 < -r.tol;

  // The dispersion curve sigma(k) along a direction e (unit vector, zero beyond the grid's dim).
  const bool ops = !opt.operators.empty();
  const int dim = opt.grid ? opt.grid->dim : 3;
  Stencil st;
  if (ops) {
    if (!opt.grid) throw UserError("linear stability: species operators need opt.grid (spacings)");
    if (dim < 1 || dim > 3)
      throw UserError("linear stability: grid dimension " + std::to_string(dim));
    check_operators(opt.operators, n, dim);
    r.operators = opt.operators;
  } else if (opt.grid) {
    st = stencil_of(*opt.grid);
  }
  std::array<double, 3> e0 = opt.direction;
  double norm = 0;
  for (int d = 0; d < 3; ++d) {
    if (d >= dim) e0[d] = 0;
    norm += e0[d] * e0[d];
  }
  if (!(norm > 0)) throw UserError("linear stability: the direction of k is zero");
  for (double& c : e0)
    c /= std::sqrt(norm);
  const Dispersion disp{n, r.jacobian.data(), r.diffusion.data(), opt.dt, opt.general_eigensolver};
  auto point = [&](const std::array<double, 3>& e, double k) {
    const std::array<double, 3> kv{k * e[0], k * e[1], k * e[2]};
    DispersionPoint p;
    if (ops) {
      double qs[kMaxSpecies];
      for (int s = 0; s < n; ++s)
        qs[s] = op_q(opt.operators[s], dim, opt.grid->h, kv);
      p = disp.at_species(qs);
    } else {
      p = disp.at(opt.grid ? q_of(st, *opt.grid, kv) : k * k);
    }
    p.k = k;
    return p;
  };
  auto k_max_along = [&](const std::array<double, 3>& e) {
    if (opt.k_max > 0) return opt.k_max;
    if (opt.grid) {
      double km = std::numeric_limits<double>::infinity();
      for (int d = 0; d < dim; ++d)
        if (std::abs(e[d]) > 1e-12) km = std::min(km, kPi / (opt.grid->h[d] * std::abs(e[d])));
      return km;
    }
    double dmin = std::numeric_limits<double>::infinity();
    for (int s = 0; s < n; ++s)
      if (D[s] > 0) dmin = std::min(dmin, D[s]);
    // All D = 0: sigma does not depend on k; any range will do.
    return std::isfinite(dmin) ? 3.0 * std::sqrt((scale > 0 ? scale : 1.0) / dmin) : 1.0;
  };

  // Sample [0, k_max] along e and refine the maximum.
  struct Ray {
    std::array<double, 3> e;
    double k_max = 0;
    std::vector<DispersionPoint> curve;
    int imax = 0;
    double kbest = 0;
    DispersionPoint best;
  };
  const int ns = opt.samples;
  auto ray = [&](const std::array<double, 3>& e) {
    Ray y;
    y.e = e;
    y.k_max = k_max_along(e);
    auto growth = [&](double k) { return point(e, k).growth; };
    y.curve.resize(ns);
    double gmax = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < ns; ++i) {
      y.curve[i] = point(e, y.k_max * i / (ns - 1));
      gmax = std::max(gmax, y.curve[i].growth);
    }
    // The first sample within round-off of the maximum (flat curves: the smallest k).
    int imax = 0;
    while (imax + 1 < ns && !(y.curve[imax].growth >= gmax - 1e-3 * r.tol))
      ++imax;
    y.imax = imax;
    // Refine the maximum inside the bracket of the best sample; keep an end if it is higher.
    const double ktol = opt.k_tol * y.k_max;
    const double a = y.curve[std::max(imax - 1, 0)].k, b = y.curve[std::min(imax + 1, ns - 1)].k;
    double kbest = golden_max(growth, a, b, ktol);
    for (double kc : {a, b, y.curve[imax].k})
      if (growth(kc) > growth(kbest)) kbest = kc;
    // Ties within round-off (flat curves, a maximum at k = 0): the smaller k.
    if (growth(a) >= growth(kbest) - 1e-3 * r.tol) kbest = a;
    y.kbest = kbest;
    y.best = point(e, kbest);
    return y;
  };

  Ray y = ray(e0);
  if (ops && dim == 2 && opt.directions > 0) {
    // The fastest direction: opt.direction unless a sampled one grows faster beyond round-off;
    // the best sample refined by golden section on the angle.
    auto dir = [](double t) { return std::array<double, 3>{std::cos(t), std::sin(t), 0}; };
    const double dtheta = kPi / opt.directions;
    int jbest = -1;
    double gbest = y.best.growth;
    for (int j = 0; j < opt.directions; ++j) {
      const double g = ray(dir(j * dtheta)).best.growth;
      if (g > gbest + 1e-3 * r.tol) gbest = g, jbest = j;
    }
    if (jbest >= 0) {
      const double t0 = jbest * dtheta;
      const double t = golden_max([&](double a) { return ray(dir(a)).best.growth; }, t0 - dtheta,
                                  t0 + dtheta, 1e-9);
      Ray yt = ray(dir(t));
      y = yt.best.growth > gbest ? std::move(yt) : ray(dir(t0));
    }
  }

  // Canonical direction: angle in [0, pi) (k and -k are the same mode).
  r.direction = y.e;
  double angle = std::atan2(y.e[1], y.e[0]);
  if (angle < 0) angle += kPi;
  if (angle >= kPi) angle -= kPi;
  r.direction_fastest = angle;
  r.k_max = y.k_max;
  r.curve = std::move(y.curve);
  const std::array<double, 3> e = y.e;
  auto growth = [&](double k) { return point(e, k).growth; };
  const int imax = y.imax;
  const double kbest = y.kbest;
  const double ktol = opt.k_tol * r.k_max;
  const DispersionPoint best = y.best;
  r.k_fastest = best.k;
  for (int d = 0; d < 3; ++d)
    r.k_vector_fastest[d] = best.k * e[d];
  r.growth_fastest = best.growth;
  r.frequency_fastest = best.frequency;
  r.wavelength_fastest = best.k > 0 ? 2 * kPi / best.k : std::numeric_limits<double>::infinity();
  r.oscillatory_fastest = best.k > 0 && best.frequency > r.tol;
  r.marginal = std::abs(best.growth) <= r.tol;
  r.turing_unstable = r.stable_homogeneous && best.growth > r.tol && best.k > 0;

  // The unstable band around k_fastest: walk the samples outwards, bisect the crossings.
  if (best.growth > r.tol) {
    r.has_band = true;
    int j = imax;
    while (j >= 0 && r.curve[j].k >= kbest)
      --j;
    while (j >= 0 && r.curve[j].growth > r.tol)
      --j;
    if (j < 0) {
      r.k_lo = 0;
    } else {
      const double hi = j + 1 < ns && r.curve[j + 1].k < kbest ? r.curve[j + 1].k : kbest;
      r.k_lo = bisect_edge(growth, r.curve[j].k, hi, r.tol, ktol);
    }
    j = imax;
    while (j < ns && r.curve[j].k <= kbest)
      ++j;
    while (j < ns && r.curve[j].growth > r.tol)
      ++j;
    if (j >= ns) {
      r.k_hi = r.k_max;
      r.band_open = true;
    } else {
      const double lo = j - 1 >= 0 && r.curve[j - 1].k > kbest ? r.curve[j - 1].k : kbest;
      r.k_hi = bisect_edge(growth, r.curve[j].k, lo, r.tol, ktol);
    }
  }
  return r;
}

StabilityResult analyse(const ModelInfo& entry, const std::vector<double>& params,
                        const std::vector<double>& D, const StabilityOptions& opt) {
  const int n = entry.nspecies;
  if (static_cast<int>(params.size()) != entry.nparams || static_cast<int>(D.size()) != n)
    throw UserError(std::string("linear stability of ") + entry.name + ": expected " +
                    std::to_string(entry.nparams) + " parameters and " + std::to_string(n) +
                    " diffusion coefficients");
  std::vector<double> u(n);
  if (!opt.u_star.empty()) {
    if (static_cast<int>(opt.u_star.size()) != n)
      throw UserError(std::string("linear stability of ") + entry.name + ": u_star needs " +
                      std::to_string(n) + " values");
    u = opt.u_star;
  } else if (!entry.steady_state(params.data(), u.data())) {
    StabilityResult r;
    r.nspecies = n;
    r.diffusion = D;
    r.grid = opt.grid;
    r.operators = opt.operators;
    r.dt = opt.dt;
    return r;
  }
  std::vector<double> J(n * n);
  entry.jacobian(u.data(), params.data(), J.data());
  StabilityResult r = analyse_jacobian(n, J.data(), D.data(), opt);
  r.u_star = u;
  return r;
}

std::vector<double> default_params(const ModelInfo& entry) {
  std::vector<double> p(entry.nparams);
  for (int i = 0; i < entry.nparams; ++i)
    p[i] = entry.params[i].def;
  return p;
}

std::vector<double> default_diffusion(const ModelInfo& entry) {
  std::vector<double> D(entry.nspecies);
  for (int s = 0; s < entry.nspecies; ++s)
    D[s] = entry.species[s].D;
  return D;
}

std::vector<double> allowed_wavenumbers(const DiscreteGrid& grid, int axis) {
  if (axis < 0 || axis >= grid.dim || grid.n[axis] < 1 || !(grid.h[axis] > 0))
    throw UserError("linear stability: axis " + std::to_string(axis) +
                    " of the grid needs n >= 1 and h > 0");
  const double L = static_cast<double>(grid.n[axis]) * grid.h[axis];
  const long long mmax = grid.periodic[axis] ? grid.n[axis] / 2 : grid.n[axis] - 1;
  std::vector<double> k(mmax + 1);
  for (long long m = 0; m <= mmax; ++m)
    k[m] = (grid.periodic[axis] ? 2 * kPi : kPi) * static_cast<double>(m) / L;
  return k;
}

namespace {

// fastest_allowed_mode with per-species operators: q_s(k) = -sum_t w_t Re prod_d e^{i k_d o_d h_d}
// from per-axis tables, every mode also with the sign combinations of its components when an
// operator is not symmetric under the reflection of each axis.
AllowedMode fastest_allowed_mode_ops(const StabilityResult& r, const DiscreteGrid& grid) {
  const int n = r.nspecies, dim = grid.dim;
  if (dim < 1 || dim > 3)
    throw UserError("linear stability: grid dimension " + std::to_string(dim));
  check_operators(r.operators, n, dim);
  const bool signs = needs_sign_scan(r.operators, dim);
  std::array<int, 3> R{0, 0, 0}; // largest |offset| per axis
  for (const auto& op : r.operators)
    for (const auto& o : op.off)
      for (int d = 0; d < 3; ++d)
        R[d] = std::max(R[d], std::abs(o[d]));
  std::array<std::vector<double>, 3> k;
  std::array<std::vector<std::complex<double>>, 3> E; // E[d][i (2R+1) + o + R] = e^{i k o h}
  std::array<long long, 3> nyquist{-1, -1, -1};       // index with k_d h_d = pi (one sign)
  for (int d = 0; d < 3; ++d) {
    k[d] = d < dim ? allowed_wavenumbers(grid, d) : std::vector<double>{0.0};
    const int w = 2 * R[d] + 1;
    E[d].resize(k[d].size() * w);
    for (size_t i = 0; i < k[d].size(); ++i)
      for (int o = -R[d]; o <= R[d]; ++o)
        E[d][i * w + o + R[d]] = std::polar(1.0, k[d][i] * o * (d < dim ? grid.h[d] : 0.0));
    if (d < dim && grid.periodic[d] && grid.n[d] % 2 == 0) nyquist[d] = grid.n[d] / 2;
  }
  const Dispersion disp{n, r.jacobian.data(), r.diffusion.data(), r.dt, r.general_eigensolver};
  AllowedMode best;
  best.growth = -std::numeric_limits<double>::infinity();
  const long long n0 = k[0].size(), n1 = k[1].size(), n2 = k[2].size();
  for (long long i2 = 0; i2 < n2; ++i2)
    for (long long i1 = 0; i1 < n1; ++i1)
      for (long long i0 = 0; i0 < n0; ++i0) {
        if (i0 == 0 && i1 == 0 && i2 == 0) continue;
        const long long idx[3] = {i0, i1, i2};
        // Axes whose sign matters; the first of them keeps its sign (k ~ -k).
        int flippable = 0, first = -1;
        if (signs)
          for (int d = 0; d < dim; ++d)
            if (idx[d] != 0 && idx[d] != nyquist[d]) {
              flippable |= 1 << d;
              if (first < 0) first = d;
            }
        for (int mask = 0; mask < (1 << dim); ++mask) {
          if ((mask & ~flippable) != 0 || (first >= 0 && (mask >> first) & 1)) continue;
          double qs[kMaxSpecies];
          for (int s = 0; s < n; ++s) {
            const SpeciesOperator& op = r.operators[s];
            double sum = 0;
            for (size_t t = 0; t < op.w.size(); ++t) {
              std::complex<double> f = 1;
              for (int d = 0; d < dim; ++d) {
                const std::complex<double> e = E[d][idx[d] * (2 * R[d] + 1) + op.off[t][d] + R[d]];
                f *= (mask >> d) & 1 ? std::conj(e) : e;
              }
              sum += op.w[t] * f.real();
            }
            qs[s] = -sum;
          }
          const DispersionPoint p = disp.at_species(qs);
          ++best.scanned;
          if (p.growth > best.growth) {
            for (int d = 0; d < 3; ++d) {
              const bool neg = (mask >> d) & 1;
              best.m[d] = neg ? -idx[d] : idx[d];
              best.k[d] = neg ? -k[d][idx[d]] : k[d][idx[d]];
            }
            best.growth = p.growth;
            best.frequency = p.frequency;
          }
        }
      }
  best.q = std::numeric_limits<double>::quiet_NaN();
  best.k_abs = std::sqrt(best.k[0] * best.k[0] + best.k[1] * best.k[1] + best.k[2] * best.k[2]);
  best.wavelength = best.k_abs > 0 ? 2 * kPi / best.k_abs : 0;
  return best;
}

} // namespace

AllowedMode fastest_allowed_mode(const StabilityResult& r, const DiscreteGrid& grid) {
  if (!r.has_steady_state)
    throw UserError("linear stability: no steady state, so no fastest allowed mode");
  if (!r.operators.empty()) return fastest_allowed_mode_ops(r, grid);
  const Stencil st = stencil_of(grid);
  std::array<std::vector<double>, 3> k, c; // wavenumbers and cos(k h) per axis
  for (int d = 0; d < 3; ++d) {
    k[d] = d < grid.dim ? allowed_wavenumbers(grid, d) : std::vector<double>{0.0};
    for (double kd : k[d])
      c[d].push_back(std::cos(kd * (d < grid.dim ? grid.h[d] : 0.0)));
  }
  const Dispersion disp{r.nspecies, r.jacobian.data(), r.diffusion.data(), r.dt,
                        r.general_eigensolver};
  AllowedMode best;
  best.growth = -std::numeric_limits<double>::infinity();
  const long long n0 = k[0].size(), n1 = k[1].size(), n2 = k[2].size();
  for (long long i2 = 0; i2 < n2; ++i2)
    for (long long i1 = 0; i1 < n1; ++i1)
      for (long long i0 = 0; i0 < n0; ++i0) {
        if (i0 == 0 && i1 == 0 && i2 == 0) continue;
        // Symmetric stencils: cos(k . off h) = prod_d cos(k_d off_d h_d) summed over the taps.
        const double cd[3] = {c[0][i0], c[1][i1], c[2][i2]};
        double s = 0;
        for (int t = 0; t < st.nterms; ++t) {
          double f = st.w[t];
          for (int d = 0; d < grid.dim; ++d)
            if (st.off[t][d] != 0) f *= cd[d];
          s += f;
        }
        const DispersionPoint p = disp.at(-s);
        ++best.scanned;
        if (p.growth > best.growth) {
          best.m = {i0, i1, i2};
          best.k = {k[0][i0], k[1][i1], k[2][i2]};
          best.q = -s;
          best.growth = p.growth;
          best.frequency = p.frequency;
        }
      }
  best.k_abs = std::sqrt(best.k[0] * best.k[0] + best.k[1] * best.k[1] + best.k[2] * best.k[2]);
  best.wavelength = best.k_abs > 0 ? 2 * kPi / best.k_abs : 0;
  return best;
}

std::vector<std::vector<double>> find_steady_states(const ModelInfo& entry,
                                                    const std::vector<double>& params,
                                                    const SteadySearch& search) {
  const int n = entry.nspecies;
  if (static_cast<int>(params.size()) != entry.nparams || n > kMaxSpecies)
    throw UserError(std::string("steady states of ") + entry.name + ": expected " +
                    std::to_string(entry.nparams) + " parameters");
  std::vector<double> own(n);
  const bool has_own = entry.steady_state(params.data(), own.data());
  std::vector<double> lo(n), hi(n);
  for (int s = 0; s < n; ++s) {
    const double h =
        2 * std::max({1.0, std::abs(entry.species[s].init), has_own ? std::abs(own[s]) : 0.0});
    lo[s] = s < static_cast<int>(search.lo.size()) ? search.lo[s] : -h;
    hi[s] = s < static_cast<int>(search.hi.size()) ? search.hi[s] : h;
  }
  // Starts per species: a grid of pts^n points (about 5,000 or fewer starts).
  static constexpr int auto_points[5] = {1, 65, 17, 9, 7};
  const int pts = search.points > 0 ? search.points
                  : n <= 4          ? auto_points[n]
                  : n <= 8          ? 3
                  : n <= 12         ? 2
                                    : 1;
  long long starts = 1;
  for (int s = 0; s < n; ++s)
    starts *= pts;

  // Start c (a grid point) into u[0..n-1]; stack arrays throughout: a search is thousands of
  // starts (4,225 for two species), once per sweep point and per stability-map point.
  auto start = [&](long long c, double* u) {
    for (int s = 0; s < n; ++s, c /= pts)
      u[s] = pts == 1 ? 0.5 * (lo[s] + hi[s]) : lo[s] + (hi[s] - lo[s]) * (c % pts) / (pts - 1);
  };
  // Residual scale: the largest |R| over the starts (a root must be 1e-10 of it).
  double rscale = 1;
  for (long long c = 0; c < starts; ++c) {
    double u[kMaxSpecies], R[kMaxSpecies];
    start(c, u);
    entry.rates(u, params.data(), R);
    for (int s = 0; s < n; ++s)
      if (std::isfinite(R[s])) rscale = std::max(rscale, std::abs(R[s]));
  }

  std::vector<std::vector<double>> found;
  const double bound = 1e3 * (1 + std::max(max_abs(lo.data(), n), max_abs(hi.data(), n)));
  auto newton = [&](double* u) { // u: the start, overwritten by the iterates
    double R[kMaxSpecies], J[kMaxSpecies * kMaxSpecies];
    for (int it = 0; it < search.max_it; ++it) {
      entry.rates(u, params.data(), R);
      entry.jacobian(u, params.data(), J);
      if (!solve_small(n, J, R)) return;
      double step = 0;
      for (int s = 0; s < n; ++s) {
        u[s] -= R[s];
        step = std::max(step, std::abs(R[s]));
      }
      if (!std::isfinite(step) || max_abs(u, n) > bound) return;
      if (step <= 1e-15 * (1 + max_abs(u, n))) break;
    }
    entry.rates(u, params.data(), R);
    double res = 0;
    for (int s = 0; s < n; ++s)
      res = std::max(res, std::abs(R[s]));
    if (!std::isfinite(res) || res > 1e-10 * rscale) return;
    // Newton converges only linearly to a double root (a fold): 1e-5 merges its copies.
    for (const auto& v : found) {
      double d = 0;
      for (int s = 0; s < n; ++s)
        d = std::max(d, std::abs(u[s] - v[s]));
      if (d <= 1e-5 * (1 + max_abs(u, n))) return;
    }
    found.emplace_back(u, u + n);
  };
  double u[kMaxSpecies];
  if (has_own) {
    std::copy(own.begin(), own.end(), u);
    newton(u);
  }
  for (long long c = 0; c < starts; ++c) {
    start(c, u);
    newton(u);
  }
  std::sort(found.begin(), found.end());
  return found;
}

std::string summary(const StabilityResult& r) {
  if (!r.has_steady_state) return "no homogeneous steady state";
  // With per-species operators in 2-D, the direction of the fastest wave vector.
  const std::string along =
      !r.operators.empty() && r.grid && r.grid->dim == 2
          ? ", direction " + fmt("%.3g", r.direction_fastest * 180 / kPi) + " deg"
          : "";
  const std::string fastest = "fastest wavelength " + fmt("%.3g", r.wavelength_fastest) + " (k " +
                              fmt("%.3g", r.k_fastest) + along + "), growth " +
                              fmt("%.3g", r.growth_fastest);
  std::string band;
  if (r.has_band)
    band = "; unstable band k in [" + fmt("%.3g", r.k_lo) + ", " + fmt("%.3g", r.k_hi) +
           (r.band_open ? "] (open: still growing at k_max)" : "]");
  if (r.hopf) {
    double w = 0, g = -std::numeric_limits<double>::infinity();
    for (const auto& l : r.eigen0)
      if (rate_of(l, r.dt) > g) g = rate_of(l, r.dt), w = std::abs(l.imag());
    std::string s = "Hopf-unstable at k = 0: growth " + fmt("%.3g", g) + ", frequency " +
                    fmt("%.3g", w) + " (period " + fmt("%.3g", 2 * kPi / w) + ")";
    if (r.k_fastest > 0) s += "; " + fastest;
    return s + band;
  }
  if (r.growth0 > r.tol)
    return "unstable at k = 0 (real eigenvalue, growth " + fmt("%.3g", r.growth0) + ")" + band;
  if (r.turing_unstable)
    return std::string(r.oscillatory_fastest ? "wave-unstable (oscillatory, frequency " +
                                                   fmt("%.3g", r.frequency_fastest) + "): "
                                             : "Turing-unstable: ") +
           fastest + band;
  if (r.marginal) return "marginal (on the instability threshold): " + fastest;
  if (r.k_fastest == 0)
    return "stable: slowest decay " + fmt("%.3g", r.growth_fastest) + " (uniform mode, k = 0)";
  return "stable: slowest decay " + fmt("%.3g", r.growth_fastest) + " at k " +
         fmt("%.3g", r.k_fastest) + " (wavelength " + fmt("%.3g", r.wavelength_fastest) + ")";
}

std::string summary(const AllowedMode& m) {
  std::string s = "fastest allowed mode m = (" + std::to_string(m.m[0]) + ", " +
                  std::to_string(m.m[1]) + ", " + std::to_string(m.m[2]) + "): wavelength " +
                  fmt("%.4g", m.wavelength) + " (|k| " + fmt("%.4g", m.k_abs) + "), growth " +
                  fmt("%.3g", m.growth);
  if (m.frequency > 0) s += ", frequency " + fmt("%.3g", m.frequency);
  return s;
}

} // namespace morphogen::analysis
