#include "app/reaction_stiffness.hpp"

#include "analysis/linear_stability.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <unordered_set>
#include <vector>

namespace morphogen {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The forward-Euler bound of a 2x2 Jacobian's decaying eigenvalues (infinity if none); sets
// the eigenvalue that gives it.
double bound_2x2(const double* J, double& re, double& im) {
  const double tr = J[0] + J[3], det = J[0] * J[3] - J[1] * J[2];
  const double disc = 0.25 * tr * tr - det;
  double best = kInf;
  if (disc >= 0) {
    const double r = std::sqrt(disc);
    for (double l : {0.5 * tr - r, 0.5 * tr + r})
      if (l < 0 && -2.0 / l < best) best = -2.0 / l, re = l, im = 0;
  } else if (tr < 0 && det > 0) { // lambda = tr/2 +- i sqrt(-disc), |lambda|^2 = det
    best = -tr / det, re = 0.5 * tr, im = std::sqrt(-disc);
  }
  return best;
}

// FNV-1a over the 64-bit words of a key's n doubles, then a final mix (splitmix64's).
struct KeyHash {
  const std::vector<double>* store;
  size_t n;
  size_t operator()(size_t idx) const {
    const double* v = store->data() + idx * n;
    uint64_t h = 1469598103934665603ull;
    for (size_t t = 0; t < n; ++t) {
      uint64_t w;
      std::memcpy(&w, v + t, sizeof w);
      h = (h ^ w) * 1099511628211ull;
    }
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    return static_cast<size_t>(h ^ (h >> 31));
  }
};
struct KeyEqual {
  const std::vector<double>* store;
  size_t n;
  bool operator()(size_t a, size_t b) const {
    return std::memcmp(store->data() + a * n, store->data() + b * n, n * sizeof(double)) == 0;
  }
};

} // namespace

EigenBound euler_bound(int n, const double* J, bool general) {
  EigenBound out{kInf};
  if (n == 2 && !general) {
    out.dt = bound_2x2(J, out.lambda_re, out.lambda_im);
    return out;
  }
  std::complex<double> ev[64];
  if (n < 1 || n > 64 || !analysis::eigenvalues(n, J, ev, true)) return out;
  for (int s = 0; s < n; ++s) {
    const double re = ev[s].real(), im = ev[s].imag();
    if (!(re < 0)) continue;
    const double b = -2.0 * re / (re * re + im * im);
    if (b < out.dt) out = {b, re, std::abs(im)};
  }
  return out;
}

CellsBound min_euler_bound(int n, long long cells, int nkey,
                           const std::function<void(long long cell, double* key)>& key,
                           const std::function<void(long long cell, double* J)>& jac,
                           long long max_eigen) {
  CellsBound out;
  const size_t nn = static_cast<size_t>(n) * static_cast<size_t>(n);
  const size_t nk = static_cast<size_t>(std::max(nkey, 0));
  std::vector<double> J(nn), prev(nk);
  auto evaluate = [&](long long c) {
    jac(c, J.data());
    ++out.evaluated;
    const EigenBound b = euler_bound(n, J.data(), n != 2);
    if (b.dt < out.bound.dt) out.bound = b, out.cell = c;
  };
  if (max_eigen <= 0) {
    const long long m = std::max(n, 2);
    max_eigen = std::max(1024LL, (1LL << 19) / (m * m * m));
  }
  // Pass 1: the distinct keys (and the first cell of each), up to max_eigen of them.
  std::vector<double> store;
  std::vector<long long> first;
  std::unordered_set<size_t, KeyHash, KeyEqual> seen(16, KeyHash{&store, nk}, KeyEqual{&store, nk});
  bool too_many = false;
  for (long long c = 0; c < cells && !too_many; ++c) {
    const size_t idx = first.size();
    store.resize((idx + 1) * nk);
    double* kc = store.data() + idx * nk;
    key(c, kc);
    // Neighbouring cells often share the key: compare with the previous cell's first.
    const bool same_as_prev = c > 0 && std::memcmp(kc, prev.data(), nk * sizeof(double)) == 0;
    if (!same_as_prev) std::memcpy(prev.data(), kc, nk * sizeof(double));
    if (!same_as_prev && seen.insert(idx).second) {
      first.push_back(c);
      too_many = static_cast<long long>(first.size()) > max_eigen;
    } else {
      store.resize(idx * nk);
    }
  }
  out.distinct = static_cast<long long>(first.size());
  if (!too_many) {
    for (long long c : first)
      evaluate(c);
    return out;
  }
  // Pass 2: every cell (n <= 2: closed forms) or a uniform sample of every stride-th cell.
  seen.clear();
  store.clear();
  store.shrink_to_fit();
  out.evaluated = 0;
  out.stride = n <= 2 ? 1 : (cells + max_eigen - 1) / max_eigen;
  for (long long c = 0; c < cells; c += out.stride)
    evaluate(c);
  return out;
}

ReactionBound reaction_dt_bound(const Simulation& sim) {
  ReactionBound out;
  out.dt = kInf;
  const ModelEntry& m = sim.model();
  const int ns = m.nspecies;
  const Grid& g = sim.grid();
  const Box& ob = g.owned();
  const ParamSet& ps = sim.params();
  std::vector<const PetscScalar*> u(static_cast<size_t>(ns)),
      p(static_cast<size_t>(m.nparams), nullptr);
  auto& state = const_cast<Simulation&>(sim).state();
  for (int s = 0; s < ns; ++s)
    MG_PETSC(VecGetArrayRead(state[static_cast<size_t>(s)], &u[static_cast<size_t>(s)]));
  for (size_t q = 0; q < p.size(); ++q)
    if (ps.field[q].get()) MG_PETSC(VecGetArrayRead(ps.field[q], &p[q]));
  const long long mx = ob.m[0], my = ob.m[1], mz = ob.m[2];
  auto cell_of = [&](long long c) {
    return std::array<PetscInt, 3>{static_cast<PetscInt>(ob.s[0] + c % mx),
                                   static_cast<PetscInt>(ob.s[1] + (c / mx) % my),
                                   static_cast<PetscInt>(ob.s[2] + c / (mx * my))};
  };
  const int np = static_cast<int>(p.size());
  // The key of a cell: its state, then its parameters.
  auto key = [&](long long c, double* v) {
    const auto [i, j, k] = cell_of(c);
    const PetscInt loc = g.local_index(i, j, k), own = g.owned_index(i, j, k);
    for (int s = 0; s < ns; ++s)
      v[s] = u[static_cast<size_t>(s)][loc];
    for (int q = 0; q < np; ++q)
      v[ns + q] = p[static_cast<size_t>(q)] ? p[static_cast<size_t>(q)][own]
                                            : ps.scalar[static_cast<size_t>(q)];
  };
  std::vector<double> kv(static_cast<size_t>(ns + np + 1)); // + 1: kv.data() + ns is valid
  const CellsBound cb =
      min_euler_bound(ns, mx * my * mz, ns + np, key, [&](long long c, double* J) {
        key(c, kv.data());
        m.jacobian(kv.data(), kv.data() + ns, J);
      });
  if (cb.cell >= 0) {
    out.dt = cb.bound.dt;
    out.cell = cell_of(cb.cell);
    out.lambda_re = cb.bound.lambda_re;
    out.lambda_im = cb.bound.lambda_im;
  }
  for (int s = 0; s < ns; ++s)
    MG_PETSC(VecRestoreArrayRead(state[static_cast<size_t>(s)], &u[static_cast<size_t>(s)]));
  for (size_t q = 0; q < p.size(); ++q)
    if (p[q]) MG_PETSC(VecRestoreArrayRead(ps.field[q], &p[q]));
  // The global minimum and the rank that holds it (MPI_MINLOC), which then shares the details.
  struct {
    double v;
    int rank;
  } mine{out.dt, 0}, best{};
  MPI_Comm comm = g.comm();
  MPI_Comm_rank(comm, &mine.rank);
  MPI_Allreduce(&mine, &best, 1, MPI_DOUBLE_INT, MPI_MINLOC, comm);
  double detail[5] = {static_cast<double>(out.cell[0]), static_cast<double>(out.cell[1]),
                      static_cast<double>(out.cell[2]), out.lambda_re, out.lambda_im};
  MPI_Bcast(detail, 5, MPI_DOUBLE, best.rank, comm);
  long long stride = cb.stride;
  MPI_Allreduce(&cb.stride, &stride, 1, MPI_LONG_LONG, MPI_MAX, comm);
  out.dt = best.v;
  for (int d = 0; d < 3; ++d)
    out.cell[static_cast<size_t>(d)] = static_cast<PetscInt>(detail[d]);
  out.lambda_re = detail[3];
  out.lambda_im = detail[4];
  out.stride = stride;
  return out;
}

void warn_if_reaction_stiff(const Simulation& sim) {
  char kind[32] = "explicit";
  MG_PETSC(PetscOptionsGetString(nullptr, nullptr, "-integrator", kind, sizeof kind, nullptr));
  if (std::string(kind) != "explicit") return;
  const ReactionBound b = reaction_dt_bound(sim);
  if (!(sim.dt() > b.dt)) return;
  int rank = 0;
  MPI_Comm_rank(sim.grid().comm(), &rank);
  if (rank != 0) return;
  char lambda[64], sample[64] = "";
  if (b.lambda_im != 0)
    std::snprintf(lambda, sizeof lambda, "%.3g +- %.3gi", b.lambda_re, b.lambda_im);
  else
    std::snprintf(lambda, sizeof lambda, "%.3g", b.lambda_re);
  if (b.stride > 1) std::snprintf(sample, sizeof sample, ", sampling 1 in %lld cells", b.stride);
  std::fprintf(stderr,
               "morphogen: warning: -dt %.4g exceeds the reaction's explicit stability bound "
               "%.3g (Jacobian eigenvalue %s at cell (%lld,%lld,%lld) of the initial state%s): "
               "the run may blow up; use -dt %.3g or less, or -integrator split\n",
               sim.dt(), b.dt, lambda, static_cast<long long>(b.cell[0]),
               static_cast<long long>(b.cell[1]), static_cast<long long>(b.cell[2]), sample,
               0.9 * b.dt);
  std::fflush(stderr);
}

} // namespace morphogen
