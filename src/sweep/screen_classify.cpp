// One parameter set of a Turing screen: see screen_classify.hpp.
#include "sweep/screen_classify.hpp"

#include "analysis/turing_2x2.hpp"

#include <cmath>
#include <numbers>

namespace morphogen::sweep {

namespace {

constexpr int kMaxN = 64;

struct StateVerdict {
  bool stable = false, turing = false;
  double q = 0, growth = 0;
};

bool all_finite(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// The verdict of one steady state u (false: its Jacobian is not finite).
bool analyse_state(const ModelInfo& entry, const std::vector<double>& params, const double* u,
                   const std::vector<double>& D, const ClassifyOptions& opt, StateVerdict& v) {
  const int n = entry.nspecies;
  double J[kMaxN * kMaxN];
  entry.jacobian(u, params.data(), J);
  if (!all_finite(J, n * n)) return false;
  if (n == 2 && !opt.general) {
    const analysis::Turing2x2 r = analysis::turing_2x2(J, D.data(), opt.zero_tol);
    if (r.handled) {
      v = {r.stable_homogeneous, r.turing_unstable, r.q_fastest, r.growth_fastest};
      return true;
    }
  }
  analysis::StabilityOptions so;
  so.samples = opt.k_samples;
  so.zero_tol = opt.zero_tol;
  const analysis::StabilityResult r = analysis::analyse_jacobian(n, J, D.data(), so);
  v = {r.stable_homogeneous, r.turing_unstable, r.k_fastest * r.k_fastest, r.growth_fastest};
  return true;
}

// Records state u with verdict v into out if it ranks above what out holds.
void consider(const double* u, int n, const StateVerdict& v, SetResult& out) {
  const Verdict now = v.turing   ? Verdict::Turing
                      : v.stable ? Verdict::Stable
                                 : Verdict::UnstableHomogeneous;
  if (static_cast<int>(now) <= static_cast<int>(out.verdict)) return;
  out.verdict = now;
  out.u.assign(u, u + n);
  out.k = now == Verdict::Turing ? std::sqrt(v.q) : 0;
  out.wavelength = out.k > 0 ? 2 * std::numbers::pi / out.k : 0;
  out.growth = now == Verdict::Turing ? v.growth : 0;
}

} // namespace

void classify_set(const ModelInfo& entry, const std::vector<double>& params,
                  const std::vector<double>& D, const ClassifyOptions& opt, SetResult& out) {
  const int n = entry.nspecies;
  out.verdict = Verdict::NoSteadyState;
  out.u.clear();
  out.k = out.wavelength = out.growth = 0;
  double u[kMaxN];
  StateVerdict v;
  const bool own = entry.steady_state(params.data(), u) && all_finite(u, n);
  if (own && !opt.all_states) {
    if (analyse_state(entry, params, u, D, opt, v)) consider(u, n, v, out);
    return;
  }
  for (const auto& s : analysis::find_steady_states(entry, params, opt.search)) {
    if (!all_finite(s.data(), n) || !analyse_state(entry, params, s.data(), D, opt, v)) continue;
    consider(s.data(), n, v, out);
    if (out.verdict == Verdict::Turing) return;
  }
}

} // namespace morphogen::sweep
